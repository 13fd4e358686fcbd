#pragma once
// Illumination of an axial map (DESIGN.md section 3, "Axial map") by stars on
// its axis. The segment from a star on the axis to a point at (x, r) lies in
// that point's meridian half-plane, where the dust is the map itself, so the
// depth is a 2D line integral through the map: the 3D bake of
// optical_depth_bake.h run on the map as an nx x nr x 1 grid of texel edge l,
// the star at (x_star, 0) on the grid's r = 0 edge. Same rule as for voxels:
// the depth stops at the texel's voxel sphere (radius 0.6204 l around the
// texel centre), a star within it sees 0. CPU and CUDA (the 3D bake's backends).
#include <vector>

#include "core/backend.h"
#include "illumination/optical_depth_bake.h"

namespace nebula {

// tau_v is [ir * nx + ix]; star_x are the stars' coordinates along the axis
// (world units from the map's x = 0). Returns one depth map per star.
BakeResult bake_axial_star_depths(int nx, int nr, float texel, const std::vector<float>& tau_v,
                                  const std::vector<float>& star_x, Backend backend);

}  // namespace nebula
