#pragma once
// The diffuse field of an axial map (docs/diffuse.md, "Axial maps"): light
// scattered at least once in another cell, as it enters each texel. Stars on
// the axis keep it axisymmetric: seen from each meridian's own frame (x' the
// way away from the axis, y' around it, z' along it) the field's harmonics
// depend on (x, r) only, so they are kept on a 2D map of cells.
//
// The bake traces photons through the map voxelized in its own frame (the
// axis along z, the grid centred on it; each voxel the mean of the texels in
// it), with the 3D bake of diffuse/ (same estimator, same photons on the CPU
// and CUDA); then each 2D cell averages, over its ring of azimuths, the 3D
// cells' harmonics turned into the meridian's frame (sh_rotate_z). The ring
// average is an estimate of the same axisymmetric field with far less noise
// than one 3D cell.
#include <vector>

#include "axial/axial_map.h"
#include "core/backend.h"
#include "diffuse/diffuse_bake.h"

namespace nebula {

class Progress;

// The map in its own frame as a 3D grid for the photons: the axis along z
// from z = 0, x and y centred on it; each voxel tau_v the
// mean over s^3 points of the texels holding them (s = 2 voxel / texel rounded
// up, at most 4: at least two points per texel across), rescaled from per texel edge to per voxel edge. `emission`
// (may be null) receives the map's emission planes alike. The photons of the
// diffuse bake and the ground truth (pipeline/) trace it.
DensityGrid voxelize_axial_frame(const AxialMap& map, float voxel,
                                 std::vector<std::vector<float>>* emission = nullptr);

struct AxialDiffuseStats {
  DiffuseBakeStats bake;   // the 3D photon pass
  GridShape grid;          // its voxelized map
  double seconds = 0;      // the whole bake: voxelization, photons, ring averages
};

// Bakes the field for stars on the map's axis (world positions). options.cells
// counts the 2D cells along the map's longer side (length or diameter); the
// photons run on a grid of twice as many voxels (never finer than a texel).
// The result's cells are {ncx along the axis, ncr from the axis, 1} of edge
// cells.voxel from the map's origin, shift 0, its harmonics in the meridian
// frames. Throws as bake_diffuse does, and Error for a star off the axis.
DiffuseField bake_axial_diffuse(const AxialMap& map, const std::vector<DiffuseBand>& bands,
                                const std::vector<StarLight>& stars, const DiffuseBakeOptions& options,
                                Backend backend, AxialDiffuseStats* stats = nullptr, Progress* progress = nullptr);

}  // namespace nebula
