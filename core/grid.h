#pragma once
// Dense 3D voxel grids: the shape (placement in the world) and a density
// field, with a POD view that kernels take by value.
#include <cstddef>
#include <vector>

#include "core/device_mirror.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

struct GridShape {
  int nx = 0, ny = 0, nz = 0;
  Vec3 origin;       // world position of the grid's minimum corner
  float voxel = 1;   // edge length l, in world units

  NEBULA_HD size_t count() const { return size_t(nx) * ny * nz; }
  NEBULA_HD size_t index(int x, int y, int z) const { return (size_t(z) * ny + y) * nx + x; }
  NEBULA_HD Vec3 centre(int x, int y, int z) const {
    return origin + voxel * Vec3{x + 0.5f, y + 0.5f, z + 0.5f};
  }
  NEBULA_HD Vec3 upper() const { return origin + voxel * Vec3{float(nx), float(ny), float(nz)}; }
};

// tau_v per voxel: the V-band extinction optical depth across one voxel edge
// (DESIGN.md section 3).
struct DensityView {
  GridShape shape;
  const float* tau_v = nullptr;
};

struct DensityGrid {
  GridShape shape;
  std::vector<float> tau_v;
  mutable DeviceMirror device_tau_v;  // the CUDA kernels' copy of tau_v, uploaded once (core/device_mirror.h)
  DensityView view() const { return {shape, tau_v.data()}; }
};

}  // namespace nebula
