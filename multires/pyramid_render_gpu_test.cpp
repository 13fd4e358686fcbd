#include <gtest/gtest.h>

#include <cmath>

#include "core/philox.h"
#include "core/test_support.h"
#include "multires/pyramid_render.h"
#include "raycast/test_scenes.h"

namespace nebula {
namespace {

// The pyramid on the GPU: bakes, renders and combines every level there
// (the combination's per-pixel steps are multires/pyramid_pixels.h on both). Levels add up, so the tolerance is the exact
// mode's 1e-4 of the peak per level.
TEST(PyramidGpu, AgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  testing::OneStarScene s;
  s.grid = testing::noise_cube(40, 0.3f, 5);  // 40 -> 20 -> 10 -> 5: odd at the last level
  s.table = testing::thin_table(0.6, 72, 10.0);
  s.finish({0.1f, 0.2f, -0.1f}, 100.0f, 0.6f, testing::oblique_camera(90, 61));
  const PyramidResult cpu = render_pyramid(s.inputs, 3, Backend::Cpu);
  const PyramidResult gpu = render_pyramid(s.inputs, 3, Backend::Cuda, true);
  ASSERT_EQ(gpu.levels.size(), 4u);
  EXPECT_EQ(gpu.levels[3].width, cpu.levels[3].width);
  double peak = 0, worst = 0;
  for (size_t i = 0; i < cpu.image.pixels.size(); ++i) {
    peak = std::max(peak, double(cpu.image.pixels[i]));
    worst = std::max(worst, double(std::fabs(cpu.image.pixels[i] - gpu.image.pixels[i])));
  }
  std::printf("pyramid, 3 levels: largest CPU-GPU difference %.3g of the peak\n", worst / peak);
  EXPECT_GT(peak, 0.0);
  EXPECT_LT(worst, 4e-4 * peak);
  for (int j = 0; j <= 3; ++j) EXPECT_EQ(cpu.report[j].table_clamps, gpu.report[j].table_clamps);
}

}  // namespace
}  // namespace nebula
