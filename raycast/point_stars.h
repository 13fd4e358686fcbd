#pragma once
// Stars drawn as attenuated point sources: flux Phi_b / (4 pi d^2) x
// exp(-tau_b) from the eye to the star, spread by a Gaussian PSF and written
// as radiance (flux over each pixel's solid angle).
#include <vector>

#include "core/bands.h"
#include "core/camera.h"
#include "core/grid.h"
#include "core/image.h"

namespace nebula {

// Adds the stars to `image` (bands in the order of `extinction_ratios`, each
// star's power in that order).
// Perspective cameras only; throws Error otherwise.
void draw_point_stars(const DensityGrid& grid, const std::vector<StarLight>& stars,
                      const std::vector<float>& extinction_ratios, const Camera& camera, float exposure,
                      double psf_sigma_pixels, Image& image);

}  // namespace nebula
