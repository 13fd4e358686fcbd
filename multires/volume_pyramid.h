#pragma once
// The volume pyramid of the 2005 paper (section 4.2; DESIGN.md section 3,
// "Multi-resolution"): level i+1 halves every axis and doubles the voxel
// edge; a coarse voxel's tau = 2 x the mean of its 8 children, so the dust
// mass (sum of tau l^2) is kept exactly.
//
// Odd sizes and non-cubic grids: each axis is halved on its own, rounding
// up (n -> ceil(n / 2)); a coarse voxel on the upper edge of an odd axis has
// children outside the grid, which count as empty space (tau 0). The coarse
// grid keeps the fine grid's origin and extends past its upper edge by at most
// one fine voxel per axis, filled with vacuum. An axis of one voxel stays one
// voxel (its single coarse voxel is half vacuum).
#include <vector>

#include "core/grid.h"

namespace nebula {

GridShape coarser_shape(const GridShape& fine);

// The most levels above level 0 that still leave a coarse grid of at least
// 2 voxels along its longest axis.
int max_pyramid_levels(const GridShape& level0);

// A per-voxel quantity integrated along one voxel edge (tau_v, or the
// emission j a ray gains crossing a voxel): 2 x mean of the children.
std::vector<float> downsample_edge_integral(const GridShape& fine, const std::vector<float>& field);

DensityGrid downsample(const DensityGrid& fine);

// Levels 0..levels; level 0 is a copy of `level0`. Throws Error when levels is
// negative or above max_pyramid_levels.
std::vector<DensityGrid> build_volume_pyramid(const DensityGrid& level0, int levels);

}  // namespace nebula
