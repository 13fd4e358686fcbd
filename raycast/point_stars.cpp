#include "raycast/point_stars.h"

#include <cmath>

#include "core/dda.h"
#include "core/error.h"
#include "core/math.h"

namespace nebula {

void draw_point_stars(const DensityGrid& grid, const std::vector<StarLight>& stars,
                      const std::vector<float>& extinction_ratios, const Camera& cam, float exposure,
                      double sigma, Image& image) {
  if (stars.empty()) return;
  if (cam.projection != Projection::Perspective)
    throw Error("output.draw_stars: drawn stars need a perspective camera for now");
  if (!(sigma > 0)) throw Error("output.star_psf_pixels: must be positive");
  const double pixel_angle = 2.0 * cam.tan_half_fov / cam.height;  // radians per pixel at the centre
  const int radius = static_cast<int>(std::ceil(4 * sigma));
  for (const StarLight& star : stars) {
    const Vec3 d = star.position - cam.position;
    const float along = dot(d, cam.forward);
    if (!(along > 0)) continue;  // behind the camera
    const float aspect = float(cam.width) / cam.height;
    const double px = ((dot(d, cam.right) / along) / (aspect * cam.tan_half_fov) + 1) * 0.5 * cam.width - 0.5;
    const double py = (1 - (dot(d, cam.up) / along) / cam.tan_half_fov) * 0.5 * cam.height - 0.5;
    const double dist2 = dot(d, d);
    const float tau_v = segment_optical_depth(grid.view(), cam.position, star.position);
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
          const double flux = star.power[b] / (4 * kPiD * dist2) * std::exp(-tau_v * extinction_ratios[b]);
          image.at(int(b), ix, iy) += static_cast<float>(exposure * flux * w / (pixel_angle * pixel_angle));
        }
      }
  }
}

}  // namespace nebula
