#pragma once
// Exact traversal of a segment through a voxel grid (Amanatides & Woo 1987,
// "A Fast Voxel Traversal Algorithm for Ray Tracing", Eurographics): every
// voxel the segment crosses, with the length inside it. No step size.
#include <cfloat>
#include <cmath>
#include <type_traits>

#include "core/grid.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

namespace detail {
NEBULA_HD float axis(const Vec3& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
}  // namespace detail

// Calls visit(voxel_index, length) for each voxel that segment a -> b
// crosses, in order, lengths in world units. The lengths telescope: they sum
// to the length of the segment inside the grid to float rounding, whatever
// rounding does at the boundaries. A segment outside the grid visits nothing.
// A visitor returning bool stops the traversal by returning false.
// Clips the ray a + t dir (unit dir), 0 <= t <= len, to the grid box:
// false when it misses, else the parameter range [t0, t1] inside.
NEBULA_HD bool clip_to_grid(const GridShape& g, Vec3 a, Vec3 dir, float len, float& t0, float& t1) {
  const int n[3] = {g.nx, g.ny, g.nz};
  t0 = 0.0f;
  t1 = len;
  for (int k = 0; k < 3; ++k) {
    const float lo = detail::axis(g.origin, k), hi = lo + g.voxel * n[k];
    const float ak = detail::axis(a, k), dk = detail::axis(dir, k);
    if (dk == 0.0f) {
      if (ak < lo || ak > hi) return false;
      continue;
    }
    float ta = (lo - ak) / dk, tb = (hi - ak) / dk;
    if (ta > tb) {
      const float s = ta;
      ta = tb;
      tb = s;
    }
    t0 = fmaxf(t0, ta);
    t1 = fminf(t1, tb);
  }
  return t0 < t1;
}

// As traverse_segment, but the visitor also receives the voxel's integer
// coordinates: visit(x, y, z, voxel_index, length). Callers that need the
// voxel's position use these instead of dividing the index (64-bit integer
// division is slow on a GPU).
//
// Where the walk keeps its per-axis state (the voxel and the next crossing on
// each axis): in named scalars, registers on the GPU, or in arrays indexed by
// the axis chosen at run time, local memory on the GPU (loads and stores
// through the caches per voxel crossed). Registers are faster for the star
// bakes, photon passes, path tracer and spectral march (docs/performance.md,
// "The voxel walk"); the band marcher's kernel, held to 64 registers for
// occupancy, is faster with the arrays (the registers would spill).
enum class WalkState { Registers, Arrays };
template <WalkState kState = WalkState::Registers, class Visit>
NEBULA_HD void traverse_segment_cells(const GridShape& g, Vec3 a, Vec3 b, Visit&& visit) {
  const Vec3 d = b - a;
  const float len = length(d);
  if (!(len > 0.0f)) return;
  const Vec3 dir = (1.0f / len) * d;
  const int n[3] = {g.nx, g.ny, g.nz};
  float t0, t1;
  if (!clip_to_grid(g, a, dir, len, t0, t1)) return;
  float inv[3];
  for (int k = 0; k < 3; ++k) {
    const float dk = detail::axis(dir, k);
    inv[k] = dk == 0.0f ? FLT_MAX : 1.0f / dk;
  }
  // The voxel holding the midpoint of the first crossing step's start.
  int cell[3], step[3];
  float t_max[3], t_delta[3];
  for (int k = 0; k < 3; ++k) {
    const float lo = detail::axis(g.origin, k);
    const float ak = detail::axis(a, k), dk = detail::axis(dir, k);
    const float p = ak + t0 * dk;
    int c = static_cast<int>(floorf((p - lo) / g.voxel));
    c = c < 0 ? 0 : (c >= n[k] ? n[k] - 1 : c);
    cell[k] = c;
    if (dk > 0.0f) {
      step[k] = 1;
      t_max[k] = (lo + (c + 1) * g.voxel - ak) * inv[k];
      t_delta[k] = g.voxel * inv[k];
    } else if (dk < 0.0f) {
      step[k] = -1;
      t_max[k] = (lo + c * g.voxel - ak) * inv[k];
      t_delta[k] = -g.voxel * inv[k];
    } else {
      step[k] = 0;
      t_max[k] = FLT_MAX;
      t_delta[k] = FLT_MAX;
    }
  }
  auto visit_cell = [&](int x, int y, int z, float chord) -> bool {
    if constexpr (std::is_same_v<decltype(visit(0, 0, 0, size_t(0), 0.0f)), bool>) {
      return visit(x, y, z, g.index(x, y, z), chord);
    } else {
      visit(x, y, z, g.index(x, y, z), chord);
      return true;
    }
  };
  float t = t0;
  if constexpr (kState == WalkState::Registers) {
    int cx = cell[0], cy = cell[1], cz = cell[2];
    float tx = t_max[0], ty = t_max[1], tz = t_max[2];
    for (int guard = n[0] + n[1] + n[2] + 3; guard > 0; --guard) {
      const int k = tx < ty ? (tx < tz ? 0 : 2) : (ty < tz ? 1 : 2);
      const float t_next = fminf(fmaxf(k == 0 ? tx : (k == 1 ? ty : tz), t), t1);
      if (!visit_cell(cx, cy, cz, t_next - t)) return;
      t = t_next;
      if (t >= t1) return;
      if (k == 0) {
        cx += step[0];
        if (cx < 0 || cx >= n[0]) return;
        tx += t_delta[0];
      } else if (k == 1) {
        cy += step[1];
        if (cy < 0 || cy >= n[1]) return;
        ty += t_delta[1];
      } else {
        cz += step[2];
        if (cz < 0 || cz >= n[2]) return;
        tz += t_delta[2];
      }
    }
  } else {
    for (int guard = n[0] + n[1] + n[2] + 3; guard > 0; --guard) {
      const int k = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
      const float t_next = fminf(fmaxf(t_max[k], t), t1);
      if (!visit_cell(cell[0], cell[1], cell[2], t_next - t)) return;
      t = t_next;
      if (t >= t1) return;
      cell[k] += step[k];
      if (cell[k] < 0 || cell[k] >= n[k]) return;
      t_max[k] += t_delta[k];
    }
  }
}

template <class Visit>
NEBULA_HD void traverse_segment(const GridShape& g, Vec3 a, Vec3 b, Visit&& visit) {
  traverse_segment_cells(g, a, b, [&](int, int, int, size_t cell, float chord) { return visit(cell, chord); });
}

// V-band extinction optical depth along segment a -> b (tau_v per voxel edge,
// so a voxel crossed over a chord c adds tau_v * c / l).
NEBULA_HD float segment_optical_depth(const DensityView& grid, Vec3 a, Vec3 b) {
  float tau = 0.0f;
  const float inv_voxel = 1.0f / grid.shape.voxel;
  traverse_segment(grid.shape, a, b,
                   [&](size_t cell, float chord) { tau += grid.tau_v[cell] * chord * inv_voxel; });
  return tau;
}

}  // namespace nebula
