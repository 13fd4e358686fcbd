// The preview's voxel sources (raycast/voxel_sources.h) against the exact
// march: the same where the light inside a voxel has no geometry to lose
// (emission), within the first-order bound of the geometry it gives up
// elsewhere, and finite at the star.
#include <gtest/gtest.h>

#include <cmath>

#include "raycast/renderer.h"
#include "raycast/test_scenes.h"

namespace nebula {
namespace {

MarchMode preview() {
  MarchMode m;
  m.voxel_sources = true;
  return m;
}

TEST(VoxelSources, EmissionAloneIsTheExactFrame) {
  DensityGrid grid = testing::noise_cube(20, 0.3f, 5);
  std::vector<float> emission(grid.tau_v.size());
  for (size_t c = 0; c < emission.size(); ++c) emission[c] = 0.01f * float(c % 7);
  RenderInputs in;
  in.density = &grid;
  in.bands = {RenderBand{{"V", 1.0f, 0.0f}, nullptr, &emission}};
  in.camera = testing::oblique_camera(40, 30);
  const Image exact = render_cpu(in, nullptr);
  in.mode = preview();
  const Image fast = render_cpu(in, nullptr);
  EXPECT_EQ(fast.pixels, exact.pixels);
}

// A star far from every voxel (r >= r_min): within a voxel 1/r^2 changes by at
// most a factor 1 +- sqrt(3) l / r and the scattering angle by sqrt(3) l / r
// radians, which moves ln p_HG by at most 3 g / (1 - g^2) per radian (the
// largest |d ln p / d theta| = 3 g sin(theta) / (1 + g^2 - 2 g cos(theta)),
// reached at cos(theta) = 2 g / (1 + g^2)). So each pixel of the preview is
// within (1 + 3 g / (1 - g^2)) sqrt(3) l / r_min of the exact one to first
// order; a quarter more leaves room for the second. The albedo and the
// optical depths do not enter: both paths read the same voxel depths and
// table rows. g = 0.9 has the largest bound (25.6 l / r_min first order).
TEST(VoxelSources, AFarStarsLightIsWithinTheGeometryBound) {
  for (double g : {0.0, 0.6, 0.9}) {
    testing::OneStarScene s;
    s.grid = testing::noise_cube(16, 0.05f, 9);
    s.table = testing::thin_table(g, 180, 2.0);
    const Vec3 star{4.0f, -20.0f, -20.0f};
    s.finish(star, 1e4f, 0.6f, testing::oblique_camera(48, 40));
    const Image exact = render_cpu(s.inputs, nullptr);
    s.inputs.mode = preview();
    const Image fast = render_cpu(s.inputs, nullptr);
    const double l = s.grid.shape.voxel;
    const double r_min = length(star) - std::sqrt(3.0);  // the grid lies within sqrt(3) of the origin
    const double bound = 1.25 * (1.0 + 3.0 * g / (1.0 - g * g)) * std::sqrt(3.0) * l / r_min;
    double peak = 0, worst = 0;
    size_t differ = 0;
    for (size_t i = 0; i < exact.pixels.size(); ++i) {
      peak = std::max(peak, double(exact.pixels[i]));
      if (exact.pixels[i] > 0) worst = std::max(worst, std::fabs(double(fast.pixels[i]) / exact.pixels[i] - 1.0));
      differ += fast.pixels[i] != exact.pixels[i];
    }
    std::printf("far star, g = %.1f: largest relative difference %.3g, bound %.3g\n", g, worst, bound);
    ASSERT_GT(peak, 0.0);
    EXPECT_GT(differ, 0u);  // the preview took its own path
    EXPECT_LE(worst, bound) << "g = " << g;
  }
}

TEST(VoxelSources, TheStarsOwnVoxelStaysFinite) {
  testing::OneStarScene s;
  s.grid = testing::cube(17, 1.0f, 0.1f);
  s.table = testing::thin_table(0.9, 72, 2.0);
  s.finish({0.0f, 0.0f, 0.0f}, 100.0f, 0.6f, testing::telescope(33, 2.2f));  // the star at a voxel's centre
  const Image exact = render_cpu(s.inputs, nullptr);
  s.inputs.mode = preview();
  const Image fast = render_cpu(s.inputs, nullptr);
  double total_exact = 0, total_fast = 0;
  for (size_t i = 0; i < fast.pixels.size(); ++i) {
    ASSERT_TRUE(std::isfinite(fast.pixels[i])) << i;
    total_exact += exact.pixels[i];
    total_fast += fast.pixels[i];
  }
  std::printf("star at a voxel centre: preview / exact total %.4f\n", total_fast / total_exact);
  EXPECT_GT(total_fast, 0.0);
}

}  // namespace
}  // namespace nebula
