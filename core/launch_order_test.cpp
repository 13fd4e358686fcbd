#include "core/launch_order.h"

#include <gtest/gtest.h>

#include <vector>

namespace nebula {
namespace {

// Every tile once, for every centre (and centres outside, clamped).
TEST(CentreOut, IsAPermutationForEveryCentre) {
  for (int n = 1; n <= 40; ++n)
    for (int c = -2; c < n + 2; ++c) {
      std::vector<int> seen(size_t(n), 0);
      for (int j = 0; j < n; ++j) {
        const int t = centre_out(j, c, n);
        ASSERT_GE(t, 0) << "n " << n << " c " << c << " j " << j;
        ASSERT_LT(t, n) << "n " << n << " c " << c << " j " << j;
        ++seen[size_t(t)];
      }
      for (int t = 0; t < n; ++t) EXPECT_EQ(seen[size_t(t)], 1) << "n " << n << " c " << c << " tile " << t;
    }
}

// Nearest first: the j-th tile lies no farther from the centre than the next.
TEST(CentreOut, StartsAtTheCentreAndMovesOut) {
  const int n = 11;
  for (int c = 0; c < n; ++c) {
    EXPECT_EQ(centre_out(0, c, n), c);
    for (int j = 1; j < n; ++j) {
      const int a = centre_out(j - 1, c, n) - c, b = centre_out(j, c, n) - c;
      EXPECT_LE(a < 0 ? -a : a, b < 0 ? -b : b) << "c " << c << " j " << j;
    }
  }
  EXPECT_EQ(centre_out(1, 5, n), 4);
  EXPECT_EQ(centre_out(2, 5, n), 6);
}

// The tile of the first point's image, else of the image's centre.
TEST(FirstTile, HoldsTheFirstStarsImageElseTheCentre) {
  CameraSettings s;
  s.position = {0, 0, -10};
  s.look_at = {0, 0, 0};
  s.up = {0, 1, 0};
  s.fov_deg = 60;
  s.width = 160;
  s.height = 96;
  const Camera c = make_camera(s);
  const LaunchTile centre = first_tile(c, {}, 16, 8);
  EXPECT_EQ(centre.x, 5);  // pixel (80, 48)
  EXPECT_EQ(centre.y, 6);
  // A star straight ahead images at the centre; one behind the camera has no image.
  const LaunchTile ahead = first_tile(c, {Vec3{0, 0, 0}, Vec3{1, 1, 0}}, 16, 8);
  EXPECT_EQ(ahead.x, centre.x);
  EXPECT_EQ(ahead.y, centre.y);
  const LaunchTile behind = first_tile(c, {Vec3{0, 0, -20}}, 16, 8);
  EXPECT_EQ(behind.x, centre.x);
  EXPECT_EQ(behind.y, centre.y);
  // Up and to the camera's right (-x here): the first row of tiles, the right half.
  const LaunchTile corner = first_tile(c, {Vec3{-4, 5, 0}}, 16, 8);
  EXPECT_EQ(corner.y, 0);
  EXPECT_GT(corner.x, centre.x);
  EXPECT_LT(corner.x, 10);
}

}  // namespace
}  // namespace nebula
