#include "illumination/optical_depth_bake.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/philox.h"

namespace nebula {
namespace {

DensityGrid uniform_grid(int n, float tau_v, float voxel = 1.0f) {
  DensityGrid grid;
  grid.shape.nx = grid.shape.ny = grid.shape.nz = n;
  grid.shape.voxel = voxel;
  grid.tau_v.assign(grid.shape.count(), tau_v);
  return grid;
}

const float kR = static_cast<float>(kVoxelSphereRadius);

// In a uniform medium the depth is tau_v (r - R) / l exactly, from a star
// anywhere inside the grid.
TEST(OpticalDepthBake, UniformMediumIsBeerLambertToTheVoxelSphere) {
  const DensityGrid grid = uniform_grid(12, 0.5f, 2.0f);
  const Vec3 star{7.3f, 11.1f, 4.2f};
  const BakeResult bake = bake_star_depths_cpu(grid, {star});
  const GridShape& g = grid.shape;
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x) {
        const float r = length(g.centre(x, y, z) - star);
        const float expected = r > kR * g.voxel ? 0.5f * (r - kR * g.voxel) / g.voxel : 0.0f;
        EXPECT_NEAR(bake.tau_v[0][g.index(x, y, z)], expected, 2e-5f * (1 + expected));
      }
}

// A star outside the grid: only the part of the path inside the grid counts.
TEST(OpticalDepthBake, StarOutsideTheGrid) {
  const DensityGrid grid = uniform_grid(8, 1.0f);
  const Vec3 star{-20.0f, 4.5f, 4.5f};
  const BakeResult bake = bake_star_depths_cpu(grid, {star});
  // Voxel (x, 4, 4) lies on the axis through the star: the path enters at x = 0.
  for (int x = 0; x < 8; ++x) {
    const float centre = x + 0.5f;
    const float expected = fmaxf(centre - kR, 0.0f);
    EXPECT_NEAR(bake.tau_v[0][grid.shape.index(x, 4, 4)], expected, 1e-5f);
  }
}

TEST(OpticalDepthBake, StarAtAVoxelCentreAndInsideAThickVoxel) {
  DensityGrid grid = uniform_grid(5, 0.2f);
  grid.tau_v[grid.shape.index(2, 2, 2)] = 1000.0f;
  const Vec3 star = grid.shape.centre(2, 2, 2);
  const BakeResult bake = bake_star_depths_cpu(grid, {star});
  const auto& d = bake.tau_v[0];
  EXPECT_EQ(d[grid.shape.index(2, 2, 2)], 0.0f);  // its own voxel: nothing in between
  // The neighbour's sphere starts R = 0.62 before its centre, 1 - R after the
  // star, still inside the star's own voxel (half-width 1/2): tau 1000 (1 - R).
  EXPECT_NEAR(d[grid.shape.index(3, 2, 2)], 1000.0f * (1 - kR), 1e-2f);
  // Two voxels away the path leaves the thick voxel after 1/2 and crosses
  // 1 - R of the next one's 0.2 as well: 1000 / 2 + 0.2 (1.5 - R).
  EXPECT_NEAR(d[grid.shape.index(4, 2, 2)], 1000.0f * 0.5f + 0.2f * (1.5f - kR), 1e-2f);
  for (float v : d) EXPECT_TRUE(std::isfinite(v) && v >= 0.0f);
  // The irradiance stays finite everywhere, the star's own voxel included.
  const float at_star = star_irradiance(1.0f, 0.0f, 1.0f, 0.0f);
  EXPECT_NEAR(at_star, 1.0f / (4 * kPi * kR * kR), 1e-6f);
  const float behind_thick = star_irradiance(1.0f, 1.0f, 1.0f, d[grid.shape.index(3, 2, 2)]);
  EXPECT_TRUE(std::isfinite(behind_thick));
  EXPECT_GE(behind_thick, 0.0f);
}

// Irradiance: inverse square outside the sphere, continuous at r = R.
TEST(OpticalDepthBake, IrradianceLaw) {
  EXPECT_NEAR(star_irradiance(4 * kPi, 2.0f, 1.0f, 0.0f), 0.25f, 1e-6f);
  EXPECT_NEAR(star_irradiance(4 * kPi, 2.0f, 1.0f, 1.0f), 0.25f * std::exp(-1.0f), 1e-6f);
  EXPECT_NEAR(star_irradiance(1.0f, kR * 0.999f, 1.0f, 0.0f), star_irradiance(1.0f, kR * 1.001f, 1.0f, 0.0f),
              3e-3f * star_irradiance(1.0f, kR, 1.0f, 0.0f));
}

TEST(OpticalDepthBake, EmptyGridIsTransparent) {
  const DensityGrid grid = uniform_grid(6, 0.0f);
  const BakeResult bake = bake_star_depths_cpu(grid, {{1, 2, 3}, {-5, -5, -5}});
  ASSERT_EQ(bake.tau_v.size(), 2u);
  for (const auto& star : bake.tau_v)
    for (float v : star) EXPECT_EQ(v, 0.0f);
}

}  // namespace
}  // namespace nebula
