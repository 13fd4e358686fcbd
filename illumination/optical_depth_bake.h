#pragma once
// Per-star illumination of every voxel (DESIGN.md section 3): the irradiance
// E_s,b(x) = Phi_s,b / (4 pi r^2) exp(-tau_b) with tau_b the optical depth
// from star s to where its light enters the voxel sphere of x, a distance R
// short of the voxel centre; the voxel's own depth is left to the table P.
//
// tau_b = tau_V * (A_b / A_V) for every band b, so one bake per star, of the
// V-band depth, serves all bands: the renderer scales it per band.
#include <vector>

#include "core/backend.h"
#include "core/dda.h"
#include "core/device_mirror.h"
#include "core/grid.h"
#include "core/hd.h"
#include "core/math.h"

namespace nebula {

// V-band optical depth from a star to the voxel sphere of voxel (x, y, z).
// A star within that sphere (r <= R) sends its light in unattenuated: 0.
NEBULA_HD float star_to_voxel_depth(const DensityView& grid, Vec3 star, int x, int y, int z) {
  const Vec3 centre = grid.shape.centre(x, y, z);
  const Vec3 d = centre - star;
  const float r = length(d);
  const float R = static_cast<float>(kVoxelSphereRadius) * grid.shape.voxel;
  if (!(r > R)) return 0.0f;
  return segment_optical_depth(grid, star, star + ((r - R) / r) * d);
}

// Irradiance on a voxel sphere at distance r from a star of band power
// `power`, behind optical depth tau_b. The rule for r <= R (the star inside
// the voxel sphere, where 1/r^2 diverges): the sphere's mean irradiance,
// power / (4 pi R^2), which is exact for any point source inside a sphere
// because all its power crosses the sphere's area 4 pi R^2.
NEBULA_HD float star_irradiance(float power, float r, float voxel, float tau_b) {
  const float R = static_cast<float>(kVoxelSphereRadius) * voxel;
  const float rr = fmaxf(r, R);
  return power * kInv4Pi / (rr * rr) * expf(-tau_b);
}

struct BakeResult {
  std::vector<std::vector<float>> tau_v;  // [star][voxel], V-band depth to the voxel sphere
  std::vector<DeviceMirror> device_tau_v; // [star]: the CUDA marchers' copies (BakedStar::depth_mirror), when kept
  double seconds = 0;                     // compute time (CUDA events on the GPU)
};

class Progress;

// Bakes every star; the grid goes to the GPU once for all stars. Progress
// (CPU only, may be null) advances in voxel rows.
BakeResult bake_star_depths(const DensityGrid& grid, const std::vector<Vec3>& stars, Backend backend,
                            Progress* progress = nullptr);
BakeResult bake_star_depths_cpu(const DensityGrid& grid, const std::vector<Vec3>& stars,
                                Progress* progress = nullptr);
BakeResult bake_star_depths_cuda(const DensityGrid& grid, const std::vector<Vec3>& stars);

}  // namespace nebula
