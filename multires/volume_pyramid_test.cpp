#include "multires/volume_pyramid.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/philox.h"

namespace nebula {
namespace {

DensityGrid random_grid(int nx, int ny, int nz, uint32_t seed) {
  DensityGrid g;
  g.shape.nx = nx;
  g.shape.ny = ny;
  g.shape.nz = nz;
  g.shape.voxel = 0.25f;
  g.shape.origin = {-1, 2, 0.5f};
  g.tau_v.resize(g.shape.count());
  for (size_t i = 0; i < g.tau_v.size(); ++i) g.tau_v[i] = 3 * philox_uniform4(seed, uint32_t(i), 0, 0, 0).u0;
  return g;
}

// Dust mass in units of sigma l^3 = tau l^2 per voxel.
double mass(const DensityGrid& g) {
  double m = 0;
  for (float t : g.tau_v) m += double(t) * g.shape.voxel * g.shape.voxel;
  return m;
}

TEST(VolumePyramid, CoarseTauIsTwiceTheMeanOfTheEightChildren) {
  const DensityGrid fine = random_grid(4, 6, 2, 7);
  const DensityGrid c = downsample(fine);
  ASSERT_EQ(c.shape.nx, 2);
  ASSERT_EQ(c.shape.ny, 3);
  ASSERT_EQ(c.shape.nz, 1);
  EXPECT_FLOAT_EQ(c.shape.voxel, 0.5f);
  EXPECT_EQ(c.shape.origin.x, fine.shape.origin.x);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 2; ++x) {
      double sum = 0;
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) sum += fine.tau_v[fine.shape.index(2 * x + dx, 2 * y + dy, dz)];
      EXPECT_NEAR(c.tau_v[c.shape.index(x, y, 0)], 2 * sum / 8, 1e-5);
    }
}

TEST(VolumePyramid, UniformDustDoublesItsDepthPerEdgeAtEveryLevel) {
  DensityGrid g = random_grid(8, 8, 8, 1);
  std::fill(g.tau_v.begin(), g.tau_v.end(), 0.3f);
  const auto levels = build_volume_pyramid(g, 2);
  ASSERT_EQ(levels.size(), 3u);
  for (float t : levels[2].tau_v) EXPECT_FLOAT_EQ(t, 1.2f);  // sigma unchanged, edge x4
}

TEST(VolumePyramid, OddAndNonCubicGridsKeepTheDustMassAndPadWithVacuum) {
  const DensityGrid g = random_grid(5, 3, 1, 3);
  const auto levels = build_volume_pyramid(g, max_pyramid_levels(g.shape));
  ASSERT_EQ(levels.size(), 3u);  // 5 -> 3 -> 2
  EXPECT_EQ(levels[1].shape.nx, 3);
  EXPECT_EQ(levels[1].shape.ny, 2);
  EXPECT_EQ(levels[1].shape.nz, 1);
  EXPECT_EQ(levels[2].shape.nx, 2);
  for (const DensityGrid& level : levels) EXPECT_NEAR(mass(level), mass(g), 1e-6 * mass(g));
  // The last coarse voxel along x (children x = 4 and the missing x = 5) holds
  // only one column of real children: the padding is vacuum.
  const DensityGrid& c = levels[1];
  double sum = 0;
  for (int y = 2; y < 3; ++y) sum += g.tau_v[g.shape.index(4, y, 0)];
  EXPECT_NEAR(c.tau_v[c.shape.index(2, 1, 0)], 2 * sum / 8, 1e-6);
}

TEST(VolumePyramid, RefusesLevelsBeyondTheCoarsestUsefulGrid) {
  const DensityGrid g = random_grid(16, 4, 4, 2);
  EXPECT_EQ(max_pyramid_levels(g.shape), 3);  // 16 -> 8 -> 4 -> 2
  EXPECT_NO_THROW(build_volume_pyramid(g, 3));
  try {
    build_volume_pyramid(g, 4);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("levels: 4 is outside 0..3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(build_volume_pyramid(g, -1), Error);
  EXPECT_EQ(build_volume_pyramid(g, 0).size(), 1u);
}

}  // namespace
}  // namespace nebula
