#pragma once
// The majorant grid of the path tracer (DESIGN.md section 3, "Ground truth"):
// per block of B^3 voxels, the largest and smallest tau_v over the block and
// a one-voxel border around it. Delta tracking samples tentative collisions
// against the block's largest value; residual ratio tracking uses the
// smallest as its control. Nebulae are sparse and high-contrast, so one
// global majorant would waste most tentative collisions in thin gas.
//
// The border makes the bounds hold for every point a float position may be
// looked up in: a point computed within rounding of a block face can land in
// the neighbouring voxel, and delta tracking is biased wherever the density
// exceeds its majorant.
#include <vector>

#include "core/grid.h"
#include "core/hd.h"

namespace nebula {

// Blocks cover the density grid from its origin; the last block along an
// axis may reach past the grid (those voxels do not exist and count for nothing).
struct MajorantView {
  GridShape shape;  // blocks: edge = block * voxel
  int block = 1;
  const float* max_tau_v = nullptr;  // [block], V band, per voxel edge
  const float* min_tau_v = nullptr;
};

struct MajorantGrid {
  GridShape shape;
  int block = 1;
  std::vector<float> max_tau_v, min_tau_v;
  MajorantView view() const { return {shape, block, max_tau_v.data(), min_tau_v.data()}; }
};

// Throws Error when block < 1 or the grid is empty.
MajorantGrid build_majorant_grid(const DensityGrid& density, int block);

}  // namespace nebula
