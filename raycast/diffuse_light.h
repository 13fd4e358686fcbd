#pragma once
// The diffuse field's light each voxel scatters towards the eye, evaluated
// once per view before the march (docs/diffuse.md). The light a voxel sends
// along a ray depends on the ray only through its direction, and every ray
// through a voxel leaves towards the same eye: so the field's harmonics are
// projected on that direction once per voxel, not once per voxel a ray
// crosses (a 1920 x 1080 frame crosses a 256^3 grid's voxels some 40 times
// over). The march then reads the result as it reads emission.
#include <type_traits>

#include "core/camera.h"
#include "core/hd.h"
#include "diffuse/spherical_harmonics.h"
#include "raycast/ray_march.h"

namespace nebula {

// Two floats at p (8-byte aligned): one 8-byte load on the device.
struct Pair {
  float v[2];
};
NEBULA_HD Pair load_pair(const float* p) {
#if NEBULA_ON_DEVICE
  const float2 q = *reinterpret_cast<const float2*>(p);
  return {{q.x, q.y}};
#else
  return {{p[0], p[1]}};
#endif
}

// The light voxel (x, y, z) of V-band depth tau_v scatters towards the eye per
// band, per unit of chord / l as the direct term: sum_l p*_l(tau_sct) D_l,
// never negative (a truncated series can dip below zero where the field is
// peaked; the light a voxel scatters cannot). kDeg: the field's degree;
// kZonal: it has zonal degrees (a separate instantiation: their code in the
// plain pass cost its kernel registers, 0.17 ms of a 1080p frame at 256^3).
// `peak` receives the response's forward peak per band, blended with the
// zonal one by the same weight as the light (DiffuseView::peak): the exact
// march reads it with the light instead of looking it up per crossing.
template <int kDeg, bool kZonal = false>
NEBULA_HD void voxel_diffuse_light(const MarchScene& s, const Camera& camera, int x, int y, int z,
                                   float (&light)[kMaxBands], float (&peak)[kMaxBands]) {
  const GridShape& g = s.density.shape;
  const size_t voxel = g.index(x, y, z);
  const float tau_v = s.density.tau_v[voxel];
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b) light[b] = peak[b] = 0.0f;
  if (!(tau_v > 0.0f)) return;
  const Vec3 centre = g.origin + g.voxel * Vec3{x + 0.5f, y + 0.5f, z + 0.5f};
  float D[kMaxBands][kDeg + 1];
  const size_t cell = s.diffuse.cell_of(x, y, z);
  const Vec3 to_eye = camera.to_eye(centre);
  s.diffuse.project<kDeg>(cell, to_eye, D);
  if constexpr (kZonal) {
    const DiffuseView& f = s.diffuse;
    const float w = f.zonal_weight(centre, to_eye);
    if (w > 0.0f) {
      // The zonal response: the harmonics' D_l below their degree, above it
      // each zonal star's sums about the direction from it (to the voxel's
      // centre; the deposits took each chord's middle), its Legendre
      // polynomials by Bonnet's recursion; blended with the harmonics' own
      // response by w. The response is linear in the D_l, so the stars are
      // taken one after the other: one star's recursion in registers at a
      // time (all of them at once, and D kept alive beside them, spilled at
      // the kernel's 64 registers: 1.35 ms of a 1080p frame at 256^3).
      // One sum per band: each degree's response interpolated between the
      // rows around tau_sct first.
      float sum[kMaxBands] = {}, frac[kMaxBands] = {}, own[kMaxBands] = {};
      const float* row[kMaxBands] = {};
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b) {
        if (!(b < s.n_bands && f.has[b])) continue;
        const float tau_sct = s.albedo[b] * tau_v * s.extinction_ratio[b];
        row[b] = f.response_row(b, tau_sct, &frac[b]);
        NEBULA_UNROLL
        for (int l = 0; l <= kDeg; ++l) {
          const float r = row[b][l] + frac[b] * (row[b][f.stride + l] - row[b][l]);
          sum[b] += r * D[b][l];
        }
        float own_peak = 0.0f;
        own[b] = f.scattered<kDeg>(b, tau_sct, D[b], &own_peak);
      }
      const int n_zonal = f.zonal - kDeg;
      const float* block = f.packed + (cell * size_t(f.coeffs) + size_t(sh_count(kDeg))) * 4;
      for (int k = 0; k < f.zonal_stars; ++k) {
        const Vec3 r = centre - f.zonal_star[k];
        const float len = length(r);
        const float mu = len > 0.0f ? dot(to_eye, r) / len : to_eye.z;
        float p_prev = 1.0f, p_l = mu;  // P_0 and P_1, then P_{l-1} and P_l
        NEBULA_UNROLL
        for (int l = 1; l < kDeg; ++l) {
          const float next = ((2.0f * l + 1.0f) * mu * p_l - float(l) * p_prev) / float(l + 1);
          p_prev = p_l;
          p_l = next;
        }
        if (kDeg == 0) p_l = 1.0f, p_prev = 0.0f;  // P_0 and "P_-1" (its weight is 0 below)
        // Two degrees at a time: one 8-byte load per row and band serves both
        // (rows of neighbouring voxels differ, so each scalar load is a
        // gather); unrolled, so that every degree's constants are known at
        // compile time.
        const float* z = block + size_t(k) * n_zonal * 4;
        NEBULA_UNROLL
        for (int pair = (kDeg + 1) / 2; pair < kMaxZonalDegree / 2 + 1; ++pair) {
          if (2 * pair > f.zonal) break;
          Quad d[2];  // y_l Z_l per band, l = 2 pair + j (0 outside kDeg < l <= zonal)
          NEBULA_UNROLL
          for (int j = 0; j < 2; ++j) {
            const int l = 2 * pair + j;
            d[j] = Quad{{0.0f, 0.0f, 0.0f, 0.0f}};
            if (l <= kDeg || l > f.zonal) continue;
            const float next = ((2.0f * l - 1.0f) / float(l)) * mu * p_l - (float(l - 1) / float(l)) * p_prev;
            p_prev = p_l;
            p_l = next;
            const float y = sqrtf((2.0f * l + 1.0f) * 0.07957747154594767f) * next;  // Y_l0: sqrt((2l + 1) / (4 pi)) P_l
            d[j] = load_quad(z + size_t(l - kDeg - 1) * 4);
            NEBULA_UNROLL
            for (int b = 0; b < kMaxBands; ++b) d[j].v[b] *= y;
          }
          NEBULA_UNROLL
          for (int b = 0; b < kMaxBands; ++b)
            if (row[b]) {
              const Pair r0 = load_pair(row[b] + 2 * pair), r1 = load_pair(row[b] + f.stride + 2 * pair);
              NEBULA_UNROLL
              for (int j = 0; j < 2; ++j) sum[b] += (r0.v[j] + frac[b] * (r1.v[j] - r0.v[j])) * d[j].v[b];
            }
        }
      }
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b)
        if (row[b]) {
          light[b] = fmaxf(0.0f, own[b] + w * (sum[b] - own[b]));
          peak[b] = f.peak(b, s.albedo[b] * tau_v * s.extinction_ratio[b], w);
        }
      return;
    }
  }
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < s.n_bands && s.diffuse.has[b]) {
      // The own response's peak, as DiffuseView::peak gives it (w = 0).
      light[b] = fmaxf(0.0f, s.diffuse.scattered<kDeg>(b, s.albedo[b] * tau_v * s.extinction_ratio[b], D[b], &peak[b]));
    }
}

// Where the light and its forward peak go: an array each per band with a
// field, null elsewhere.
struct DiffuseLightPlanes {
  float* band[kMaxBands] = {};
  float* peak[kMaxBands] = {};
};

// Writes the light of voxels x_begin..x_end - 1 of row (y, z) into `out`: the
// unit of work of the CPU loop (a row) and the CUDA kernel (a voxel).
template <int kDeg, bool kZonal = false>
NEBULA_HD void diffuse_light_row(const MarchScene& s, const Camera& camera, int y, int z, int x_begin, int x_end,
                                 const DiffuseLightPlanes& out) {
  const GridShape& g = s.density.shape;
  for (int x = x_begin; x < x_end; ++x) {
    float light[kMaxBands], peak[kMaxBands];
    voxel_diffuse_light<kDeg, kZonal>(s, camera, x, y, z, light, peak);
    const size_t voxel = g.index(x, y, z);
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b)
      if (out.band[b]) {
        out.band[b][voxel] = light[b];
        out.peak[b][voxel] = peak[b];
      }
  }
}

}  // namespace nebula
