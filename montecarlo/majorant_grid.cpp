#include "montecarlo/majorant_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>

#include "core/error.h"

namespace nebula {

MajorantGrid build_majorant_grid(const DensityGrid& d, int block) {
  if (block < 1 || block > 256) throw Error("majorant grid: block must be 1 to 256 voxels, got " + std::to_string(block));
  const GridShape& g = d.shape;
  if (g.count() == 0 || d.tau_v.size() != g.count()) throw Error("majorant grid: empty or inconsistent density grid");
  MajorantGrid m;
  m.block = block;
  m.shape.nx = (g.nx + block - 1) / block;
  m.shape.ny = (g.ny + block - 1) / block;
  m.shape.nz = (g.nz + block - 1) / block;
  m.shape.origin = g.origin;
  m.shape.voxel = g.voxel * block;
  m.max_tau_v.assign(m.shape.count(), 0.0f);
  m.min_tau_v.assign(m.shape.count(), 0.0f);
  // Slabs of blocks in parallel: each block is written once, by one thread.
  tbb::parallel_for(0, m.shape.nz, [&](int bz) {
    for (int by = 0; by < m.shape.ny; ++by)
      for (int bx = 0; bx < m.shape.nx; ++bx) {
        float hi = 0.0f, lo = 3.0e38f;
        const int x0 = std::max(0, bx * block - 1), x1 = std::min(g.nx, (bx + 1) * block + 1);
        const int y0 = std::max(0, by * block - 1), y1 = std::min(g.ny, (by + 1) * block + 1);
        const int z0 = std::max(0, bz * block - 1), z1 = std::min(g.nz, (bz + 1) * block + 1);
        for (int z = z0; z < z1; ++z)
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
              const float v = d.tau_v[g.index(x, y, z)];
              hi = std::max(hi, v);
              lo = std::min(lo, v);
            }
        m.max_tau_v[m.shape.index(bx, by, bz)] = hi;
        m.min_tau_v[m.shape.index(bx, by, bz)] = std::max(0.0f, std::min(lo, hi));
      }
  });
  return m;
}

}  // namespace nebula
