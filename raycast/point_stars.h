#pragma once
// Stars drawn as attenuated point sources, in every camera kind, spread by a
// Gaussian PSF and written as radiance: the flux at the eye Phi_b / (4 pi d^2)
// x exp(-tau_b) over the pixel's solid angle where the star appears
// (perspective, fisheye; core/camera.h project_point), or for the
// orthographic telescope the star's intensity Phi_b / (4 pi) x exp(-tau_b),
// seen along the view direction, over a pixel's area.
#include <vector>

#include "core/bands.h"
#include "core/camera.h"
#include "core/grid.h"
#include "core/image.h"

namespace nebula {

// Adds the stars to `image` (bands in the order of `extinction_ratios`, each
// star's power in that order).
void draw_point_stars(const DensityGrid& grid, const std::vector<StarLight>& stars,
                      const std::vector<float>& extinction_ratios, const Camera& camera, float exposure,
                      double psf_sigma_pixels, Image& image);

}  // namespace nebula
