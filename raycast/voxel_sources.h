#pragma once
// The interactive preview's shortcut (MarchMode::voxel_sources): the light
// each voxel sends towards the eye, evaluated once per view at the voxel's
// centre, then only carried to the eye by the march. The exact march
// evaluates it per ray and voxel, over the ray's chord: 1/r^2 averaged over
// the chord and the scattering angle at its light's midpoint
// (illumination/chord_irradiance.h). A frame crosses each voxel many times
// (a 256 x 256 frame of a 128^3 grid about 6 times), so the preview does
// that work once per voxel instead, at the price of the geometry inside a
// voxel: the angle at the voxel's centre, and 1/r^2 there softened by the
// voxel's size (the star's own voxel stays finite). Its error against the
// exact frame is measured in raycast/voxel_sources_test.cpp and stated in
// docs/marcher.md.
#include "core/camera.h"
#include "core/hd.h"
#include "raycast/diffuse_light.h"
#include "raycast/ray_march.h"

namespace nebula {

// Voxel (x, y, z)'s light towards the eye per band, per unit of chord / l:
// emission + sum over stars of E P(tau_sct, theta) + the diffuse field's
// light (kDeg its degree; -1: no field), and in `peak` the field's forward
// peak (0 without a field). Table clamps are counted in *clamps.
template <int kDeg, bool kZonal = false>
NEBULA_HD void voxel_source(const MarchScene& s, const Camera& camera, int x, int y, int z, float (&out)[kMaxBands],
                            float (&peak)[kMaxBands], int* clamps) {
  const GridShape& g = s.density.shape;
  const size_t cell = g.index(x, y, z);
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b) {
    out[b] = (b < s.n_bands && s.emission[b]) ? s.emission[b][cell] : 0.0f;
    peak[b] = 0.0f;
  }
  const float tau_v = s.density.tau_v[cell];
  if (!(tau_v > 0.0f)) return;
  const Vec3 centre = g.origin + g.voxel * Vec3{x + 0.5f, y + 0.5f, z + 0.5f};
  const Vec3 to_eye = camera.to_eye(centre);
  for (int k = 0; k < s.n_stars; ++k)
    add_star_light(s, s.stars[k].position, s.stars[k].power, s.stars[k].depth_v[cell],
                   point_irradiance(centre, s.stars[k].position, g.voxel), tau_v, to_eye, out, clamps);
  if constexpr (kDeg >= 0) {
    float light[kMaxBands];
    voxel_diffuse_light<kDeg, kZonal>(s, camera, x, y, z, light, peak);
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b)
      if (b < s.n_bands) out[b] += light[b];
  }
}

// Where the sources go: one array per band of the scene; the field's forward
// peak one per band with a field (null elsewhere).
struct VoxelSourcePlanes {
  float* band[kMaxBands] = {};
  float* peak[kMaxBands] = {};
};

// Voxels x_begin..x_end - 1 of row (y, z): the unit of work of the CPU loop
// (a row) and the CUDA kernel (a voxel). Returns the table clamps.
template <int kDeg, bool kZonal = false>
NEBULA_HD int voxel_source_row(const MarchScene& s, const Camera& camera, int y, int z, int x_begin, int x_end,
                               const VoxelSourcePlanes& out) {
  const GridShape& g = s.density.shape;
  int clamps = 0;
  for (int x = x_begin; x < x_end; ++x) {
    float source[kMaxBands], peak[kMaxBands];
    voxel_source<kDeg, kZonal>(s, camera, x, y, z, source, peak, &clamps);
    const size_t cell = g.index(x, y, z);
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b) {
      if (b < s.n_bands) out.band[b][cell] = source[b];
      if (out.peak[b]) out.peak[b][cell] = peak[b];
    }
  }
  return clamps;
}

// Calls f(std::integral_constant<int, degree>) with the scene's field degree,
// -1 without a field.
template <class F>
void dispatch_source_degree(const MarchScene& s, F&& f) {
  if (!s.has_diffuse) {
    f(std::integral_constant<int, -1>());
    return;
  }
  dispatch_diffuse_degree(s.diffuse.degree, std::forward<F>(f));
}

}  // namespace nebula
