// Issue 13: "in the exact mode the voxels around a star show as a hard-edged
// saturated square on a fisheye frame". That square was the voxel sphere's cap
// on 1/r^2 (Phi / (4 pi R^2), until 2026-11-23): every ray through the star's
// voxel got the same capped irradiance, a plateau one voxel wide. With the
// chord-mean 1/r^2 (illumination/chord_irradiance.h) the pixels follow the
// 1/r cusp of the scattered light instead. This pins it down on a dome master.
#include <gtest/gtest.h>

#include <cmath>

#include "raycast/test_scenes.h"

namespace nebula {
namespace {

TEST(FisheyeNearAStar, NoPlateauTheWidthOfAVoxel) {
  testing::OneStarScene s;
  s.grid = testing::cube(16, 1.0f, 0.05f);  // uniform and thin: any step would be the marcher's own
  s.table = testing::thin_table(0.6);
  CameraSettings cs;
  cs.projection = Projection::Fisheye;
  cs.position = {0.0f, -0.6f, 0.0f};
  cs.look_at = {0, 0, 0};
  cs.up = {0, 0, 1};
  cs.width = cs.height = 257;  // the star's voxel (0.125 across at 0.6) spans about 17 pixels
  s.finish({0.01f, 0.02f, -0.03f}, 1.0f, 0.6f, make_camera(cs));
  const Image image = render_cpu(s.inputs, nullptr);
  int px = 0, py = 0;
  float peak = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.at(0, x, y) > peak) peak = image.at(0, x, y), px = x, py = y;
  ASSERT_GT(peak, 0.0f);
  // A plateau one voxel wide would put about 17 x 17 pixels within 5% of the peak.
  int near_peak = 0;
  for (float v : image.pixels) near_peak += v >= 0.95f * peak ? 1 : 0;
  EXPECT_LE(near_peak, 4);
  // Away from the centre pixels the profile is the cusp: from r to r + 1 pixels it falls by
  // about (r + 1) / r <= 4/3 for r >= 3; a voxel's hard edge would be a larger step.
  double worst = 1;
  for (int d = 3; d < 40; ++d)
    for (const auto& [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const float inner = image.at(0, px + dx * d, py + dy * d), outer = image.at(0, px + dx * (d + 1), py + dy * (d + 1));
      worst = std::fmax(worst, double(inner) / outer);
      EXPECT_GE(inner, outer) << "not falling away from the star at " << d << " pixels";
    }
  EXPECT_LT(worst, 1.5);  // 4/3 with 12% for the pixel footprint and the half-light point (measured: 1.414)
  RecordProperty("worst_step", std::to_string(worst));
  std::printf("largest fall from one pixel to the next, 3 to 40 pixels from the star: factor %.3f\n", worst);
}

}  // namespace
}  // namespace nebula
