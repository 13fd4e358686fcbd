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
#include "diffuse/zonal_light.h"
#include "raycast/ray_march.h"

namespace nebula {

// The light voxel (x, y, z) of V-band depth tau_v scatters towards the eye per
// band, per unit of chord / l as the direct term: sum_l p*_l(tau_sct) D_l,
// never negative (a truncated series can dip below zero where the field is
// peaked; the light a voxel scatters cannot). kDeg: the field's degree;
// kZonal: it has zonal degrees (diffuse/zonal_light.h; a separate
// instantiation: their code in the plain pass cost its kernel registers, 0.17
// ms of a 1080p frame at 256^3).
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
  field_scattered_light<kDeg, kZonal>(s, s.diffuse, tau_v, s.diffuse.cell_of(x, y, z), centre, camera.to_eye(centre),
                                      light, peak);
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
