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

// The three camera kinds, off axis and with a non-square frame where allowed.
std::vector<Camera> every_kind() {
  std::vector<Camera> out;
  CameraSettings s;
  s.position = {0.3f, -0.2f, -6.0f};
  s.look_at = {0, 0, 0};
  s.up = {0, 1, 0};
  s.width = 160;
  s.height = 120;
  s.fov_deg = 50;
  out.push_back(make_camera(s));
  s.projection = Projection::Orthographic;
  s.ortho_width = 3.0;
  out.push_back(make_camera(s));
  s.projection = Projection::Fisheye;
  s.width = s.height = 150;
  out.push_back(make_camera(s));
  return out;
}

// project_point is the inverse of ray_through: the ray through the image
// point it returns passes through the point.
TEST(ProjectPoint, TheRayThroughTheImagePointMeetsThePoint) {
  for (const Camera& c : every_kind())
    for (Vec3 p : {Vec3{0, 0, 0}, Vec3{0.7f, 0.4f, 0.5f}, Vec3{-0.9f, -0.6f, 1.5f}, Vec3{1.1f, -0.3f, -2.0f}}) {
      const std::optional<ImagePoint> at = project_point(c, p);
      ASSERT_TRUE(at) << to_string(c.projection);
      Vec3 o, d;
      ASSERT_TRUE(c.ray_through(float(at->x), float(at->y), o, d)) << to_string(c.projection);
      const Vec3 to_p = p - o;
      const Vec3 off = to_p - dot(to_p, d) * d;  // p's distance from the ray
      EXPECT_GT(dot(to_p, d), 0.0f);
      EXPECT_LT(length(off), 2e-5f * length(to_p)) << to_string(c.projection) << " " << p.x << " " << p.y << " " << p.z << " at " << at->x << " " << at->y;
    }
}

// The pixel measure against the pixel's corners: the solid angle of the four
// corner rays' quadrilateral (two spherical triangles by their excess, small
// here), or the area of the corner origins' parallelogram.
TEST(ProjectPoint, PixelMeasureIsThePixelsSolidAngleOrArea) {
  auto triangle = [](Vec3 a, Vec3 b, Vec3 c) {  // Van Oosterom & Strackee 1983
    const double num = std::fabs(double(dot(a, cross(b, c))));
    const double den = 1.0 + double(dot(a, b)) + double(dot(b, c)) + double(dot(c, a));
    return 2.0 * std::atan2(num, den);
  };
  for (const Camera& c : every_kind())
    for (Vec3 p : {Vec3{0.1f, 0.05f, 0}, Vec3{0.8f, 0.5f, 0.3f}, Vec3{-1.0f, 0.6f, -1.0f}}) {
      const std::optional<ImagePoint> at = project_point(c, p);
      ASSERT_TRUE(at);
      const float x = std::floor(float(at->x)), y = std::floor(float(at->y));
      Vec3 o[4], d[4];
      const float cx[4] = {x, x + 1, x + 1, x}, cy[4] = {y, y, y + 1, y + 1};
      for (int k = 0; k < 4; ++k) ASSERT_TRUE(c.ray_through(cx[k], cy[k], o[k], d[k]));
      double expected = 0;
      if (c.projection == Projection::Orthographic)
        expected = length(cross(o[1] - o[0], o[3] - o[0]));
      else
        expected = triangle(d[0], d[1], d[2]) + triangle(d[0], d[2], d[3]);
      // The measure is the density at the point; the pixel's own varies by
      // about a pixel's angle across it.
      EXPECT_NEAR(at->pixel_measure / expected, 1.0, 0.02) << to_string(c.projection) << " at " << at->x << ", " << at->y;
    }
}

TEST(ProjectPoint, NothingBehindTheCameraOrOutsideTheDome) {
  const std::vector<Camera> c = every_kind();
  EXPECT_FALSE(project_point(c[0], Vec3{0.3f, -0.2f, -8.0f}));
  EXPECT_FALSE(project_point(c[1], Vec3{0.3f, -0.2f, -8.0f}));
  EXPECT_FALSE(project_point(c[2], Vec3{0.3f, -0.2f, -8.0f}));  // 180 degrees from the zenith
  EXPECT_TRUE(project_point(c[2], Vec3{5.0f, -0.2f, -5.5f}));    // 87 degrees from the zenith
}

}  // namespace
}  // namespace nebula
