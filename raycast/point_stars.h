#pragma once
// Stars drawn as attenuated point sources: flux Phi_b / (4 pi d^2) x
// exp(-tau_b) from the eye to the star, spread by a Gaussian PSF and written
// as radiance (flux over each pixel's solid angle).
#include <vector>

#include "core/grid.h"
#include "core/image.h"
#include "raycast/camera.h"

namespace nebula {

struct PointStar {
  Vec3 position;
  std::vector<float> power;  // per band, L_sun
};

// Adds the stars to `image` (bands in the order of `extinction_ratios`).
// Perspective cameras only; throws Error otherwise.
void draw_point_stars(const DensityGrid& grid, const std::vector<PointStar>& stars,
                      const std::vector<float>& extinction_ratios, const Camera& camera, float exposure,
                      double psf_sigma_pixels, Image& image);

}  // namespace nebula
