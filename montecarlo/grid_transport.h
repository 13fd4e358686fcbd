#pragma once
// Photon transport through a voxel grid of piecewise-constant dust, written
// once for host and device and shared by the ground truth (truth/) and the
// diffuse-field bake (diffuse/): delta tracking for free flights and residual
// ratio tracking for transmittance, both against a majorant grid
// (majorant_grid.h). In a band, sigma_ext = tau_v * scale with scale =
// (A_b / A_V) / l.
#include <cstdint>

#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "montecarlo/majorant_grid.h"

namespace nebula {

// The dust and its majorants, by value (pointers to host or device memory).
struct GridMedium {
  DensityView density;
  MajorantView majorant;
};

// tau_v of the voxel holding p (clamped to the grid).
NEBULA_HD float tau_v_at(const DensityView& d, Vec3 p) {
  const GridShape& g = d.shape;
  const float inv = 1.0f / g.voxel;
  int x = static_cast<int>(floorf((p.x - g.origin.x) * inv));
  int y = static_cast<int>(floorf((p.y - g.origin.y) * inv));
  int z = static_cast<int>(floorf((p.z - g.origin.z) * inv));
  x = x < 0 ? 0 : (x >= g.nx ? g.nx - 1 : x);
  y = y < 0 ? 0 : (y >= g.ny ? g.ny - 1 : y);
  z = z < 0 ? 0 : (z >= g.nz ? g.nz - 1 : z);
  return d.tau_v[g.index(x, y, z)];
}

// A length beyond which a ray from `origin` has left the grid.
NEBULA_HD float beyond_grid(const GridShape& g, Vec3 origin) {
  const Vec3 span = g.upper() - g.origin;
  return length(origin - (g.origin + 0.5f * span)) + length(span) + g.voxel;
}

// Delta tracking from `origin` along unit `dir` in a band whose sigma_ext is
// tau_v * scale: true and the collision point when a real collision happens
// inside the grid, false when the ray leaves it. `tentative` counts the
// tentative collisions.
template <class Rng>
NEBULA_HD bool delta_track(const GridMedium& s, float scale, Vec3 origin, Vec3 dir, Rng& rng, Vec3& hit,
                           uint64_t& tentative) {
  const GridShape& g = s.density.shape;
  float t0, t1;
  if (!clip_to_grid(g, origin, dir, beyond_grid(g, origin), t0, t1)) return false;
  float xi = -logf(rng.next());  // majorant optical depth to the next tentative collision
  float t = t0;
  bool collided = false;
  traverse_segment_cells(s.majorant.shape, origin + t0 * dir, origin + t1 * dir,
                         [&](int, int, int, size_t cell, float chord) -> bool {
                           const float m = s.majorant.max_tau_v[cell] * scale;
                           float left = chord;
                           if (m > 0.0f) {
                             while (xi < m * left) {
                               const float step = xi / m;
                               t += step;
                               left -= step;
                               ++tentative;
                               const Vec3 p = origin + t * dir;
                               if (rng.next() * m < tau_v_at(s.density, p) * scale) {
                                 hit = p;
                                 collided = true;
                                 return false;
                               }
                               xi = -logf(rng.next());
                             }
                             xi -= m * left;
                           }
                           t += left;
                           return true;
                         });
  return collided;
}

// Residual ratio tracking (Novak, Selle & Jarosz 2014) of the transmittance
// from a to b: per majorant block, exp(-min * chord) exactly, times the
// product of (1 - (sigma - min) / (max - min)) over tentative points drawn
// at rate max - min. Unbiased; exact (no tentative point) in uniform blocks.
template <class Rng>
NEBULA_HD float ratio_track(const GridMedium& s, float scale, Vec3 a, Vec3 b, Rng& rng, uint64_t& tentative) {
  const GridShape& g = s.density.shape;
  const Vec3 d = b - a;
  const float len = length(d);
  if (!(len > 0.0f)) return 1.0f;
  const Vec3 dir = (1.0f / len) * d;
  float t0, t1;
  if (!clip_to_grid(g, a, dir, len, t0, t1)) return 1.0f;
  float weight = 1.0f, control = 0.0f;
  float t = t0;
  traverse_segment_cells(s.majorant.shape, a + t0 * dir, a + t1 * dir,
                         [&](int, int, int, size_t cell, float chord) -> bool {
                           const float lo = s.majorant.min_tau_v[cell] * scale;
                           const float residual = s.majorant.max_tau_v[cell] * scale - lo;
                           control += lo * chord;
                           if (residual > 0.0f) {
                             float local = -logf(rng.next()) / residual;
                             while (local < chord) {
                               ++tentative;
                               const float sigma = tau_v_at(s.density, a + (t + local) * dir) * scale;
                               // In [0, 1] by the majorant grid's border; fmaxf never acts.
                               weight *= fmaxf(0.0f, 1.0f - (sigma - lo) / residual);
                               if (!(weight > 0.0f)) return false;
                               local += -logf(rng.next()) / residual;
                             }
                           }
                           t += chord;
                           return true;
                         });
  return weight > 0.0f ? weight * expf(-control) : 0.0f;
}

}  // namespace nebula
