#pragma once
// The diffuse field's light each voxel scatters towards the eye, evaluated
// once per view before the march (docs/diffuse.md). The light a voxel sends
// along a ray depends on the ray only through its direction, and every ray
// through a voxel leaves towards the same eye: so the field's harmonics are
// projected on that direction once per voxel, not once per voxel a ray
// crosses (a 1920 x 1080 frame crosses a 256^3 grid's voxels some 40 times
// over). The march then reads the result as it reads emission.
#include "core/camera.h"
#include "core/hd.h"
#include "raycast/ray_march.h"

namespace nebula {

// The light voxel (x, y, z) of V-band depth tau_v scatters towards the eye per
// band, per unit of chord / l as the direct term: sum_l p*_l(tau_sct) D_l,
// never negative (a truncated series can dip below zero where the field is
// peaked; the light a voxel scatters cannot). kDeg: the field's degree.
template <int kDeg>
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
  const DiffuseView& f = s.diffuse;
  const float w = f.zonal_weight(centre, to_eye);
  if (w > 0.0f) {
    // The zonal response: the harmonics' D_l below their degree, above it
    // each zonal star's sums about the direction from it (to the voxel's
    // centre; the deposits took each chord's middle); blended with the harmonics' own response by w.
    const int n_zonal = f.zonal - kDeg;
    float Dz[kMaxBands][kMaxZonalDegree + 1];
    for (int b = 0; b < kMaxBands; ++b)
      for (int l = 0; l <= f.zonal; ++l) Dz[b][l] = l <= kDeg ? D[b][l] : 0.0f;
    const float* c = f.packed + cell * size_t(f.coeffs) * 4;
    for (int k = 0; k < f.zonal_stars; ++k) {
      const Vec3 r = centre - f.zonal_star[k];
      const float len = length(r);
      const float mu = len > 0.0f ? dot(to_eye, r) / len : to_eye.z;
      float yz[kMaxZonalDegree];
      zonal_basis(kDeg + 1, f.zonal, mu, yz);
      const float* block = c + size_t(sh_count(kDeg) + k * n_zonal) * 4;
      for (int j = 0; j < n_zonal; ++j)
        for (int b = 0; b < kMaxBands; ++b) Dz[b][kDeg + 1 + j] += yz[j] * block[4 * j + b];
    }
    for (int b = 0; b < kMaxBands; ++b)
      if (b < s.n_bands && f.has[b]) {
        const float tau_sct = s.albedo[b] * tau_v * s.extinction_ratio[b];
        float peak = 0.0f;
        const float own = f.scattered<kDeg>(b, tau_sct, D[b], &peak);
        light[b] = fmaxf(0.0f, own + w * (f.scattered_zonal(b, tau_sct, Dz[b]) - own));
      }
    return;
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
template <int kDeg>
NEBULA_HD void diffuse_light_row(const MarchScene& s, const Camera& camera, int y, int z, int x_begin, int x_end,
                                 const DiffuseLightPlanes& out) {
  const GridShape& g = s.density.shape;
  for (int x = x_begin; x < x_end; ++x) {
    float light[kMaxBands];
    voxel_diffuse_light<kDeg>(s, camera, x, y, z, light);
    const size_t voxel = g.index(x, y, z);
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b)
      if (out.band[b]) out.band[b][voxel] = light[b];
  }
}

}  // namespace nebula
