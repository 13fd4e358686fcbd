#include "raycast/point_stars.h"

#include <cmath>
#include <optional>

#include "core/dda.h"
#include "core/error.h"
#include "core/math.h"

namespace nebula {

void draw_point_stars(const DensityGrid& grid, const std::vector<StarLight>& stars,
                      const std::vector<float>& extinction_ratios, const Camera& cam, float exposure,
                      double sigma, Image& image) {
  if (stars.empty()) return;
  if (!(sigma > 0)) throw Error("output.star_psf_pixels: must be positive");
  const int radius = static_cast<int>(std::ceil(4 * sigma));
  for (const StarLight& star : stars) {
    const std::optional<ImagePoint> at = project_point(cam, star.position);
    if (!at) continue;  // behind the camera, or outside the dome
    const double px = at->x - 0.5, py = at->y - 0.5;  // in pixel indices
    // What reaches the eye: the flux at the eye, over a pixel's solid angle
    // (perspective, fisheye); or, for the orthographic telescope, the star's
    // intensity Phi / (4 pi) over a pixel's area, along the view direction from
    // the image plane.
    double spread = 0;
    Vec3 eye = cam.position;
    if (cam.projection == Projection::Orthographic) {
      eye = star.position - dot(star.position - cam.position, cam.forward) * cam.forward;
      spread = 4 * kPiD * at->pixel_measure;
    } else {
      const Vec3 d = star.position - cam.position;
      spread = 4 * kPiD * double(dot(d, d)) * at->pixel_measure;
    }
    const float tau_v = segment_optical_depth(grid.view(), eye, star.position);
    const int cx = static_cast<int>(std::lround(px)), cy = static_cast<int>(std::lround(py));
    // The PSF's weights over the pixels it covers, normalised to 1 (whole PSF).
    double norm = 0;
    for (int y = -radius; y <= radius; ++y)
      for (int x = -radius; x <= radius; ++x) {
        const double dx = cx + x - px, dy = cy + y - py;
        norm += std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
      }
    for (int y = -radius; y <= radius; ++y)
      for (int x = -radius; x <= radius; ++x) {
        const int ix = cx + x, iy = cy + y;
        if (ix < 0 || iy < 0 || ix >= cam.width || iy >= cam.height) continue;
        const double dx = ix - px, dy = iy - py;
        const double w = std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma)) / norm;
        for (size_t b = 0; b < extinction_ratios.size(); ++b) {
          const double radiance = star.power[b] / spread * std::exp(-tau_v * extinction_ratios[b]);
          image.at(int(b), ix, iy) += static_cast<float>(exposure * radiance * w);
        }
      }
  }
}

}  // namespace nebula
