#include "axial/axial_bake.h"

#include "core/error.h"

namespace nebula {

BakeResult bake_axial_star_depths(int nx, int nr, float texel, const std::vector<float>& tau_v,
                                  const std::vector<float>& star_x, Backend backend) {
  if (tau_v.size() != size_t(nx) * size_t(nr)) throw Error("axial bake: tau_v does not match the map's size");
  DensityGrid grid;
  grid.shape.nx = nx;
  grid.shape.ny = nr;
  grid.shape.nz = 1;
  grid.shape.voxel = texel;
  grid.shape.origin = {0, 0, 0};
  grid.tau_v = tau_v;
  std::vector<Vec3> stars;
  for (float x : star_x) stars.push_back(Vec3{x, 0.0f, 0.5f * texel});  // in the grid's middle plane
  return bake_star_depths(grid, stars, backend);
}

}  // namespace nebula
