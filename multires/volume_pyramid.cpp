#include "multires/volume_pyramid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>

#include "core/error.h"

namespace nebula {

GridShape coarser_shape(const GridShape& fine) {
  GridShape c = fine;
  c.nx = (fine.nx + 1) / 2;
  c.ny = (fine.ny + 1) / 2;
  c.nz = (fine.nz + 1) / 2;
  c.voxel = 2 * fine.voxel;
  return c;
}

int max_pyramid_levels(const GridShape& level0) {
  int n = std::max({level0.nx, level0.ny, level0.nz}), levels = 0;
  while (n > 2) {
    n = (n + 1) / 2;
    ++levels;
  }
  return levels;
}

std::vector<float> downsample_edge_integral(const GridShape& fine, const std::vector<float>& field) {
  if (field.size() != fine.count())
    throw Error("downsample: field has " + std::to_string(field.size()) + " values, grid " +
                std::to_string(fine.count()));
  const GridShape c = coarser_shape(fine);
  std::vector<float> out(c.count());
  tbb::parallel_for(0, c.nz, [&](int z) {
    for (int y = 0; y < c.ny; ++y)
      for (int x = 0; x < c.nx; ++x) {
        double sum = 0;  // missing children (odd axes) are vacuum
        for (int dz = 0; dz < 2; ++dz)
          for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
              const int fx = 2 * x + dx, fy = 2 * y + dy, fz = 2 * z + dz;
              if (fx < fine.nx && fy < fine.ny && fz < fine.nz) sum += field[fine.index(fx, fy, fz)];
            }
        out[c.index(x, y, z)] = static_cast<float>(2.0 * sum / 8.0);
      }
  });
  return out;
}

DensityGrid downsample(const DensityGrid& fine) {
  DensityGrid c;
  c.shape = coarser_shape(fine.shape);
  c.tau_v = downsample_edge_integral(fine.shape, fine.tau_v);
  return c;
}

std::vector<DensityGrid> build_volume_pyramid(const DensityGrid& level0, int levels) {
  const int most = max_pyramid_levels(level0.shape);
  if (levels < 0 || levels > most)
    throw Error("levels: " + std::to_string(levels) + " is outside 0.." + std::to_string(most) + " for a grid of " +
                std::to_string(level0.shape.nx) + "x" + std::to_string(level0.shape.ny) + "x" +
                std::to_string(level0.shape.nz) + " voxels (the coarsest level keeps at least 2 along its longest axis)");
  std::vector<DensityGrid> out{level0};
  for (int i = 0; i < levels; ++i) out.push_back(downsample(out.back()));
  return out;
}

}  // namespace nebula
