#include <gtest/gtest.h>

#include <cmath>

#include "core/philox.h"
#include "core/test_support.h"
#include "illumination/optical_depth_bake.h"

namespace nebula {
namespace {

// The CPU and GPU bake the same function. They differ only in float rounding
// (nvcc contracts multiply-adds): crossing distances are measured from the
// star, so each boundary may move by a few ulps of the path length L, i.e.
// by 4 L 2^-24, and hand that much of the densest voxel's depth to its
// neighbour. The bound sums that over every boundary (nx + ny + nz at most),
// plus 1e-5 relative for the summation itself.
TEST(OpticalDepthBakeGpu, AgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  DensityGrid grid;
  grid.shape.nx = 40;
  grid.shape.ny = 33;
  grid.shape.nz = 27;
  grid.shape.voxel = 0.7f;
  grid.shape.origin = {-3, 1, 2};
  grid.tau_v.resize(grid.shape.count());
  float densest = 0;
  for (size_t c = 0; c < grid.tau_v.size(); ++c) {
    grid.tau_v[c] = 5.0f * philox_uniform4(9, 0, uint32_t(c), 0, 0).u0;
    densest = fmaxf(densest, grid.tau_v[c]);
  }
  // Inside, outside, and exactly at a voxel centre.
  const std::vector<Vec3> stars{{10.1f, 12.3f, 9.7f}, {-30.0f, 50.0f, 5.0f}, grid.shape.centre(3, 4, 5)};
  const BakeResult cpu = bake_star_depths_cpu(grid, stars);
  const BakeResult gpu = bake_star_depths_cuda(grid, stars);
  ASSERT_EQ(gpu.tau_v.size(), stars.size());
  for (size_t s = 0; s < stars.size(); ++s) {
    double worst = 0;
    for (size_t c = 0; c < grid.tau_v.size(); ++c) {
      const int x = int(c % grid.shape.nx), y = int(c / grid.shape.nx % grid.shape.ny),
                z = int(c / (size_t(grid.shape.nx) * grid.shape.ny));
      const double L = length(grid.shape.centre(x, y, z) - stars[s]);
      const double boundaries = grid.shape.nx + grid.shape.ny + grid.shape.nz;
      const double bound =
          1e-5 * cpu.tau_v[s][c] + boundaries * 4 * L * 0x1p-24 / grid.shape.voxel * densest + 1e-7;
      worst = std::fmax(worst, std::fabs(gpu.tau_v[s][c] - cpu.tau_v[s][c]) / bound);
    }
    std::printf("star %zu: worst CPU-GPU difference %.3g of its bound\n", s, worst);
    EXPECT_LE(worst, 1.0) << "star " << s;
  }
}

}  // namespace
}  // namespace nebula
