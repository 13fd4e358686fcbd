#include "core/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace nebula {
namespace {

TEST(Camera, PerspectiveRaysSpanTheFieldOfView) {
  CameraSettings s;
  s.position = {0, 0, -10};
  s.look_at = {0, 0, 0};
  s.up = {0, 1, 0};
  s.fov_deg = 60;
  s.width = 201;
  s.height = 101;
  const Camera c = make_camera(s);
  Vec3 o, d;
  ASSERT_TRUE(c.ray(100, 50, o, d));  // the centre pixel looks straight ahead
  EXPECT_NEAR(d.z, 1.0f, 1e-6f);
  // The top row's centre is half a pixel inside the vertical half-angle of 30 degrees.
  c.ray(100, 0, o, d);
  const float half_pixel = 0.5f * 2 * std::tan(30 * kPi / 180) / 101;
  EXPECT_NEAR(d.y / d.z, std::tan(30 * kPi / 180) - half_pixel, 1e-5f);
  EXPECT_GT(d.y, 0.0f);  // row 0 is the top
  c.ray(0, 50, o, d);
  EXPECT_LT(dot(d, c.right), 0.0f);  // column 0 is the left
  // right = forward x up: looking along +z with y up, +x is on the left.
  EXPECT_NEAR(c.right.x, -1.0f, 1e-6f);
}

TEST(Camera, OrthographicRaysAreParallel) {
  CameraSettings s;
  s.projection = Projection::Orthographic;
  s.position = {0, 0, -10};
  s.look_at = {0, 0, 0};
  s.ortho_width = 4;
  s.width = 40;
  s.height = 20;
  const Camera c = make_camera(s);
  Vec3 o, d;
  c.ray(0, 0, o, d);
  EXPECT_NEAR(d.z, 1.0f, 1e-7f);
  // Pixels are 0.1 wide: the top-left pixel's centre is half a pixel in.
  EXPECT_NEAR(dot(o, c.right), -2.0f + 0.05f, 1e-5f);
  EXPECT_NEAR(o.y, 1.0f - 0.05f, 1e-5f);
}

TEST(Camera, ACoarserCameraSeesTheSameFrameWithBiggerPixels) {
  CameraSettings s;
  s.projection = Projection::Orthographic;
  s.position = {0, 0, -10};
  s.look_at = {0, 0, 0};
  s.ortho_width = 4;
  s.width = 41;  // odd: the last coarse pixel reaches one fine pixel past the frame
  s.height = 20;
  const Camera fine = make_camera(s);
  const Camera coarse = coarser_camera(coarser_camera(fine));
  EXPECT_EQ(coarse.width, 11);
  EXPECT_EQ(coarse.height, 5);
  Vec3 o, d, o0, o1, o2, o3, unused;
  // A level-2 pixel's centre is the mean of the 4 x 4 fine pixel centres it spans.
  coarse.ray(3, 2, o, d);
  fine.ray(12, 8, o0, unused);
  fine.ray(15, 11, o1, unused);
  EXPECT_NEAR(o.x, 0.5f * (o0.x + o1.x), 1e-5f);
  EXPECT_NEAR(o.y, 0.5f * (o0.y + o1.y), 1e-5f);
  // Perspective: the same field of view, so the centre pixel still looks ahead.
  s.projection = Projection::Perspective;
  s.width = 40;
  const Camera p = coarser_camera(make_camera(s));
  p.ray(9, 4, o2, d);
  p.ray(10, 5, o3, unused);
  EXPECT_NEAR((d + unused).x, 0.0f, 1e-6f);
  EXPECT_NEAR((d + unused).y, 0.0f, 1e-6f);
}

TEST(Camera, FisheyeIsAzimuthalEquidistant) {
  CameraSettings s;
  s.projection = Projection::Fisheye;
  s.position = {0, 0, 0};
  s.look_at = {0, 0, 1};
  s.up = {0, 1, 0};
  s.width = s.height = 101;
  const Camera c = make_camera(s);
  Vec3 o, d;
  ASSERT_TRUE(c.ray(50, 50, o, d));
  EXPECT_NEAR(d.z, 1.0f, 1e-6f);
  // Half-way to the rim is 45 degrees from the zenith.
  ASSERT_TRUE(c.ray(75, 50, o, d));
  const float rho = (2 * 75.5f / 101 - 1);
  EXPECT_NEAR(std::acos(d.z), rho * 0.5f * kPi, 1e-5f);
  EXPECT_FALSE(c.ray(0, 0, o, d));  // corners lie outside the dome
}

TEST(Camera, RefusesDegenerateSettings) {
  CameraSettings s;
  s.look_at = s.position;
  EXPECT_THROW(make_camera(s), Error);
  s = {};
  s.up = s.look_at - s.position;
  EXPECT_THROW(make_camera(s), Error);
  s = {};
  s.fov_deg = 180;
  EXPECT_THROW(make_camera(s), Error);
  s = {};
  s.projection = Projection::Fisheye;
  s.width = 100;
  s.height = 50;
  EXPECT_THROW(make_camera(s), Error);
  s = {};
  s.projection = Projection::Orthographic;
  EXPECT_THROW(make_camera(s), Error);  // no ortho_width
}

}  // namespace
}  // namespace nebula
