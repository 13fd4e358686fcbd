#pragma once
// The pixels around a star's image, where one ray cannot stand for its pixel.
// A star inside dust lights the pixels at its image with light that changes
// within each of them: 1/b from the star (b the distance from it), and with
// forward scattering the phase's peak, seen from the star under angles b/s
// that a single ray per pixel samples at one b only (on axial_lopsided at
// g = 0.9 one ray per pixel left the four pixels at the star 0.57 of the
// mean of 8 x 8 rays). These pixels are marched with side x side stratified rays, each
// standing for its own sub-pixel (a footprint side times narrower), and
// averaged in a fixed order: on the CPU and the GPU the same sums. The band,
// axial and spectral marchers all do it (docs/marcher.md, "The star's own pixels").
#include <vector>

#include "core/bands.h"
#include "core/camera.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

// Rays per side in the pixels whose centre lies within kStarPixelCore pixels
// of a star's image (per axis), and in the rest within kStarPixelReach.
constexpr int kStarPixelCoreSide = 32, kStarPixelSide = 8;
constexpr float kStarPixelCore = 1.25f, kStarPixelReach = 3.0f;

struct StarPixel {
  int x = 0, y = 0;
  int side = 1;    // rays per side
  int first = 0;   // its first ray among all star pixels' rays
};

// The stars' positions.
std::vector<Vec3> star_positions(const std::vector<BakedStar>& stars);

// The star pixels of `camera` for stars at these positions (each pixel once,
// row by row), their rays numbered consecutively; `rays` gets their total.
std::vector<StarPixel> star_pixels(const Camera& camera, const std::vector<Vec3>& stars, int* rays);

// Ray k (0 <= k < side^2) of a star pixel: the centre of its stratum.
NEBULA_HD bool star_pixel_ray(const Camera& c, const StarPixel& p, int k, Vec3& origin, Vec3& dir) {
  const float inv = 1.0f / float(p.side);
  return c.ray_through(float(p.x) + (float(k % p.side) + 0.5f) * inv, float(p.y) + (float(k / p.side) + 0.5f) * inv,
                       origin, dir);
}

// A sub-pixel's footprint: `side` times narrower than the pixel's.
NEBULA_HD RayFootprint sub_pixel_footprint(RayFootprint f, int side) {
  f.width_at_eye /= float(side);
  f.spread /= float(side);
  return f;
}

// The star pixel that ray i (0 <= i < total) belongs to: binary search on `first`.
NEBULA_HD int star_pixel_of_ray(const StarPixel* pixels, int n, int i) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (pixels[mid].first <= i) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

// Ray i (0 <= i < rays) of the star pixels `list` (n of them): march(origin,
// dir, side, out, stride) marches it as a sub-pixel `side` times narrower
// than its pixel, writes its n_planes values to out[b * stride] and returns
// its table clamps; here out = sub + i, stride = rays. A ray the camera
// cannot trace (outside a fisheye's dome) gives zeros. The marchers' CPU
// loops and CUDA kernels all call this.
template <class March>
NEBULA_HD int march_star_pixel_ray(const Camera& camera, const StarPixel* list, int n, int rays, int i, int n_planes,
                                   float* sub, March march) {
  const StarPixel& p = list[star_pixel_of_ray(list, n, i)];
  float* out = sub + i;
  Vec3 origin, dir;
  if (!star_pixel_ray(camera, p, i - p.first, origin, dir)) {
    for (int b = 0; b < n_planes; ++b) out[size_t(b) * rays] = 0.0f;
    return 0;
  }
  return int(march(origin, dir, p.side, out, size_t(rays)));
}

// A star pixel's value from its rays' (sub: plane b of ray i at
// sub[b * rays + i], the rays numbered as StarPixel::first says), summed in
// the rays' order, times the exposure, stored as a ray's value is ([plane][y][x]).
NEBULA_HD void store_star_pixel(const float* sub, size_t rays, const StarPixel& p, int n_planes, float exposure,
                                float* pixels, int width, int height) {
  const size_t plane = size_t(width) * height;
  const int n = p.side * p.side;
  for (int b = 0; b < n_planes; ++b) {
    float sum = 0.0f;
    for (int k = 0; k < n; ++k) sum += sub[size_t(b) * rays + size_t(p.first + k)];
    pixels[b * plane + size_t(p.y) * width + p.x] = exposure * (sum / float(n));
  }
}

}  // namespace nebula
