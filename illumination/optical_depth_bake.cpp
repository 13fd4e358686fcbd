#include "illumination/optical_depth_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>

#include "core/progress.h"

namespace nebula {

BakeResult bake_star_depths_cpu(const DensityGrid& grid, const std::vector<Vec3>& stars, Progress* progress) {
  BakeResult out;
  const auto start = std::chrono::steady_clock::now();
  const DensityView view = grid.view();
  const GridShape& g = grid.shape;
  for (const Vec3& star : stars) {
    std::vector<float> depth(g.count());
    // One task per z-y row of voxels.
    tbb::parallel_for(tbb::blocked_range<int>(0, g.ny * g.nz), [&](const auto& rows) {
      for (int row = rows.begin(); row != rows.end(); ++row) {
        const int y = row % g.ny, z = row / g.ny;
        for (int x = 0; x < g.nx; ++x) depth[g.index(x, y, z)] = star_to_voxel_depth(view, star, x, y, z);
      }
      if (progress) progress->add(rows.size());
    });
    out.tau_v.push_back(std::move(depth));
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

BakeResult bake_star_depths(const DensityGrid& grid, const std::vector<Vec3>& stars, Backend backend,
                            Progress* progress) {
  return backend == Backend::Cuda ? bake_star_depths_cuda(grid, stars) : bake_star_depths_cpu(grid, stars, progress);
}

}  // namespace nebula
