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
#include "raycast/ray_march.h"

namespace nebula {

// The light voxel (x, y, z) of V-band depth tau_v scatters towards the eye per
// band, per unit of chord / l as the direct term: sum_l p*_l(tau_sct) D_l,
// never negative (a truncated series can dip below zero where the field is
// peaked; the light a voxel scatters cannot). kDeg: the field's degree;
// kZonal: it has zonal degrees (a separate instantiation: their code in the
// plain pass cost its kernel registers, 0.17 ms of a 1080p frame at 256^3).
template <int kDeg, bool kZonal = false>
NEBULA_HD void voxel_diffuse_light(const MarchScene& s, const Camera& camera, int x, int y, int z,
                                   float (&light)[kMaxBands]) {
  const GridShape& g = s.density.shape;
  const size_t voxel = g.index(x, y, z);
  const float tau_v = s.density.tau_v[voxel];
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b) light[b] = 0.0f;
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
      // The zonal response, degree by degree without arrays: the harmonics' D_l
      // below their degree, above it each zonal star's sums about the direction
      // from it (to the voxel's centre; the deposits took each chord's middle),
      // its Legendre polynomials by Bonnet's recursion; blended with the
      // harmonics' own response by w.
      const int n_zonal = f.zonal - kDeg;
      // The loops over zonal stars are unrolled to kMaxZonalStars on the
      // device, so these arrays stay in registers.
      float mu[kMaxZonalStars], p_prev[kMaxZonalStars], p_l[kMaxZonalStars];
      NEBULA_UNROLL
      for (int k = 0; k < kMaxZonalStars; ++k) {
        if (k >= f.zonal_stars) break;
        const Vec3 r = centre - f.zonal_star[k];
        const float len = length(r);
        mu[k] = len > 0.0f ? dot(to_eye, r) / len : to_eye.z;
        p_prev[k] = 1.0f;  // P_0, then P_{l-1}
        p_l[k] = mu[k];    // P_1, then P_l
        for (int l = 1; l < kDeg; ++l) {
          const float next = ((2.0f * l + 1.0f) * mu[k] * p_l[k] - float(l) * p_prev[k]) / float(l + 1);
          p_prev[k] = p_l[k];
          p_l[k] = next;
        }
        if (kDeg == 0) p_l[k] = 1.0f, p_prev[k] = 0.0f;  // P_0 and "P_-1" (its weight is 0 below)
      }
      float s0[kMaxBands] = {}, s1[kMaxBands] = {}, frac[kMaxBands] = {};
      const float* row[kMaxBands] = {};
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b) {
        if (!(b < s.n_bands && f.has[b])) continue;
        row[b] = f.response_row(b, s.albedo[b] * tau_v * s.extinction_ratio[b], &frac[b]);
        for (int l = 0; l <= kDeg; ++l) {
          s0[b] += row[b][l] * D[b][l];
          s1[b] += row[b][f.stride + l] * D[b][l];
        }
      }
      const float* block = f.packed + (cell * size_t(f.coeffs) + size_t(sh_count(kDeg))) * 4;
      for (int l = kDeg + 1; l <= f.zonal; ++l) {
        const float norm = sqrtf((2.0f * l + 1.0f) * 0.07957747154594767f);  // sqrt((2l + 1) / (4 pi))
        float Dl[kMaxBands] = {};
        NEBULA_UNROLL
        for (int k = 0; k < kMaxZonalStars; ++k) {
          if (k >= f.zonal_stars) break;
          const float next = ((2.0f * l - 1.0f) * mu[k] * p_l[k] - float(l - 1) * p_prev[k]) / float(l);
          p_prev[k] = p_l[k];
          p_l[k] = next;
          const Quad q = load_quad(block + (size_t(k) * n_zonal + size_t(l - kDeg - 1)) * 4);
          NEBULA_UNROLL
          for (int b = 0; b < kMaxBands; ++b) Dl[b] += norm * next * q.v[b];
        }
        NEBULA_UNROLL
        for (int b = 0; b < kMaxBands; ++b)
          if (row[b]) {
            s0[b] += row[b][l] * Dl[b];
            s1[b] += row[b][f.stride + l] * Dl[b];
          }
      }
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b)
        if (row[b]) {
          float peak = 0.0f;
          const float own = f.scattered<kDeg>(b, s.albedo[b] * tau_v * s.extinction_ratio[b], D[b], &peak);
          const float zonal = s0[b] + frac[b] * (s1[b] - s0[b]);
          light[b] = fmaxf(0.0f, own + w * (zonal - own));
        }
      return;
    }
  }
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < s.n_bands && s.diffuse.has[b]) {
      float peak = 0.0f;
      light[b] = fmaxf(0.0f, s.diffuse.scattered<kDeg>(b, s.albedo[b] * tau_v * s.extinction_ratio[b], D[b], &peak));
    }
}

// Where the light goes: an array per band with a field, null elsewhere.
struct DiffuseLightPlanes {
  float* band[kMaxBands] = {};
};

// Writes the light of voxels x_begin..x_end - 1 of row (y, z) into `out`: the
// unit of work of the CPU loop (a row) and the CUDA kernel (a voxel).
template <int kDeg, bool kZonal = false>
NEBULA_HD void diffuse_light_row(const MarchScene& s, const Camera& camera, int y, int z, int x_begin, int x_end,
                                 const DiffuseLightPlanes& out) {
  const GridShape& g = s.density.shape;
  for (int x = x_begin; x < x_end; ++x) {
    float light[kMaxBands];
    voxel_diffuse_light<kDeg, kZonal>(s, camera, x, y, z, light);
    const size_t voxel = g.index(x, y, z);
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b)
      if (out.band[b]) out.band[b][voxel] = light[b];
  }
}

}  // namespace nebula
