#pragma once
// The star pixels' rays on the CPU (illumination/star_pixels.h), for the
// marchers' CPU loops: march(origin, dir, narrowing, out, stride) marches one
// ray standing for a sub-pixel `narrowing` times narrower than its pixel,
// writes its n_planes values to out[b * stride] and returns its table clamps.
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdint>
#include <vector>

#include "illumination/star_pixels.h"

namespace nebula {

template <class March>
void march_star_pixels_cpu(const Camera& camera, const std::vector<Vec3>& stars, int n_planes, float exposure,
                           float* image, March march, std::atomic<uint64_t>& clamps) {
  int rays = 0;
  const std::vector<StarPixel> cells = star_pixels(camera, stars, &rays);
  if (cells.empty()) return;
  std::vector<float> sub(size_t(rays) * size_t(n_planes), 0.0f);
  tbb::parallel_for(0, rays, [&](int i) {
    const int n = march_star_pixel_ray(camera, cells.data(), int(cells.size()), rays, i, n_planes, sub.data(), march);
    if (n) clamps += uint64_t(n);
  });
  const int n = int(cells.size());
  for (int c = 0; c < n; ++c)
    for (int b = 0; b < n_planes; ++b) reduce_star_cell(sub.data(), size_t(rays), cells.data(), c, b);
  for (int i = 0; i < n; ++i)
    for (int b = 0; b < n_planes; ++b)
      store_star_pixel(sub.data(), size_t(rays), cells.data(), i, b, exposure, image, camera.width, camera.height);
}

}  // namespace nebula
