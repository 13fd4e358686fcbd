#pragma once
// The star pixels' rays on the CPU (raycast/star_pixels.h), for the marchers'
// CPU loops: march(origin, dir, side, out, stride) marches one ray standing
// for a sub-pixel `side` times narrower than its pixel, writes its n_planes
// values to out[b * stride] and returns its table clamps.
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
  const std::vector<StarPixel> pixels = star_pixels(camera, stars, &rays);
  if (pixels.empty()) return;
  std::vector<float> sub(size_t(rays) * size_t(n_planes), 0.0f);
  tbb::parallel_for(0, rays, [&](int i) {
    const int n = march_star_pixel_ray(camera, pixels.data(), int(pixels.size()), rays, i, n_planes, sub.data(), march);
    if (n) clamps += uint64_t(n);
  });
  for (const StarPixel& p : pixels)
    store_star_pixel(sub.data(), size_t(rays), p, n_planes, exposure, image, camera.width, camera.height);
}

}  // namespace nebula
