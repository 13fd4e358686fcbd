#pragma once
// The reference ray marcher (DESIGN.md section 3, "Ray marching"): exact,
// step-free voxel traversal; a voxel crossed over a chord c adds radiance
// T_in (sum_s E_s P(tau_sct, theta_s) + j) c / l, then T *= exp(-tau_b c / l).
// Written once for host and device.
#include <cstdint>

#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "illumination/optical_depth_bake.h"
#include "tables/table_lookup.h"

namespace nebula {

constexpr int kMaxBands = 4;

// One star as the marcher sees it: band powers and its baked V-band depth
// to every voxel sphere.
struct StarView {
  Vec3 position;
  float power[kMaxBands];  // band luminosity, L_sun
  const float* depth_v;    // [voxel]
};

// Everything a ray needs, by value (pointers to host or device memory).
struct MarchScene {
  DensityView density;
  int n_bands = 0;
  float extinction_ratio[kMaxBands];  // A_b / A_V
  float albedo[kMaxBands];
  TableView table[kMaxBands];         // P per band; unused where albedo is 0
  const float* emission[kMaxBands];   // j per voxel and band, or null
  const StarView* stars = nullptr;
  int n_stars = 0;
  float min_transmittance = 1e-4f;    // rays stop once every band is below this
};

struct RayResult {
  float radiance[kMaxBands];
  float transmittance[kMaxBands];
  int table_clamps;
};

// Marches from `origin` along unit `dir` through the whole grid.
NEBULA_HD RayResult march_ray(const MarchScene& s, Vec3 origin, Vec3 dir) {
  RayResult out{};
  for (int b = 0; b < kMaxBands; ++b) out.transmittance[b] = 1.0f;
  const GridShape& g = s.density.shape;
  // A far point beyond the grid; traverse_segment clips to the grid box.
  const Vec3 span = g.upper() - g.origin;
  const Vec3 mid = g.origin + 0.5f * span;
  const float far = length(origin - mid) + length(span) + g.voxel;
  const float inv_voxel = 1.0f / g.voxel;
  const Vec3 to_eye = -dir;
  traverse_segment(g, origin, origin + far * dir, [&](size_t cell, float chord) -> bool {
    const float tau_v = s.density.tau_v[cell];
    float source[kMaxBands];
    for (int b = 0; b < s.n_bands; ++b) source[b] = s.emission[b] ? s.emission[b][cell] : 0.0f;
    if (tau_v > 0.0f && s.n_stars > 0) {
      const int x = static_cast<int>(cell % g.nx);
      const int y = static_cast<int>((cell / g.nx) % g.ny);
      const int z = static_cast<int>(cell / (size_t(g.nx) * g.ny));
      const Vec3 centre = g.centre(x, y, z);
      for (int k = 0; k < s.n_stars; ++k) {
        const StarView& star = s.stars[k];
        const Vec3 d = centre - star.position;
        const float r = length(d);
        // theta: between the light's direction (star to voxel) and the way to the eye.
        const float mu = r > 0.0f ? dot(d, to_eye) / r : 0.0f;
        const float depth = star.depth_v[cell];
        for (int b = 0; b < s.n_bands; ++b) {
          if (!(s.albedo[b] > 0.0f)) continue;
          const float tau_b = tau_v * s.extinction_ratio[b];
          const float e = star_irradiance(star.power[b], r, g.voxel, depth * s.extinction_ratio[b]);
          source[b] += e * s.table[b].lookup(s.albedo[b] * tau_b, mu, &out.table_clamps);
        }
      }
    }
    const float fraction = chord * inv_voxel;
    bool visible = false;
    for (int b = 0; b < s.n_bands; ++b) {
      out.radiance[b] += out.transmittance[b] * source[b] * fraction;
      out.transmittance[b] *= expf(-tau_v * s.extinction_ratio[b] * fraction);
      visible = visible || out.transmittance[b] >= s.min_transmittance;
    }
    return visible;
  });
  return out;
}

}  // namespace nebula
