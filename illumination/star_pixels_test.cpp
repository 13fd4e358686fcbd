#include "illumination/star_pixels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace nebula {
namespace {

Camera telescope(int pixels) {
  CameraSettings s;
  s.projection = Projection::Orthographic;
  s.position = {0, 0, -10};
  s.look_at = {0, 0, 0};
  s.ortho_width = 2.0;  // pixels of 2 / pixels
  s.width = s.height = pixels;
  return make_camera(s);
}

// The pixels at a star's image: those whose centre lies within the reach of
// it per axis, the finest rays where it is within the core; each pixel once
// however many stars ask for it, their rays numbered one after the other.
TEST(StarPixels, AreThePixelsAroundEachStarsImageOnce) {
  const Camera c = telescope(16);
  int rays = 0;
  // A star on the common corner of pixels 7 and 8 (image x, y = 8).
  std::vector<StarPixel> p = star_pixels(c, {{0, 0, 0}}, &rays);
  // Centres at 0.5, 1.5, 2.5 from the corner on each side: 6 x 6 pixels, the 2 x 2 at 0.5 in the core.
  ASSERT_EQ(p.size(), 36u);
  int core = 0, total = 0;
  for (const StarPixel& q : p) {
    EXPECT_GE(q.x, 5);
    EXPECT_LE(q.x, 10);
    EXPECT_EQ(q.first, total);
    total += q.side * q.side;
    const bool in_core = (q.x == 7 || q.x == 8) && (q.y == 7 || q.y == 8);
    EXPECT_EQ(q.side, in_core ? kStarPixelCoreSide : kStarPixelSide) << q.x << ", " << q.y;
    core += in_core;
  }
  EXPECT_EQ(core, 4);
  EXPECT_EQ(rays, total);
  // Every ray finds its pixel.
  for (int i = 0; i < rays; i += 37) {
    const StarPixel& q = p[size_t(star_pixel_of_ray(p.data(), int(p.size()), i))];
    EXPECT_LE(q.first, i);
    EXPECT_LT(i, q.first + q.side * q.side);
  }
  // Two stars a pixel apart share pixels, each once, at the finer side.
  p = star_pixels(c, {{0, 0, 0}, {0.125f, 0, 0}}, &rays);
  std::set<std::pair<int, int>> seen;
  for (const StarPixel& q : p) EXPECT_TRUE(seen.insert({q.x, q.y}).second) << q.x << ", " << q.y;
  EXPECT_EQ(p.size(), 42u);  // x from 5 to 11
  // A star outside the frame near its edge keeps the pixels inside; one behind the camera has none.
  const Vec3 edge{1.05f, 0, 0};
  const double at = project_point(c, edge)->x;  // 0.4 outside the frame
  p = star_pixels(c, {edge}, &rays);
  EXPECT_EQ(p.size(), 18u);  // 3 columns x 6 rows
  for (const StarPixel& q : p) EXPECT_LE(std::fabs(q.x + 0.5 - at), kStarPixelReach);
  EXPECT_TRUE(star_pixels(c, {{0, 0, -20}}, &rays).empty());
  EXPECT_EQ(rays, 0);
}

// The rays of a star pixel are its strata's centres, inside the pixel.
TEST(StarPixels, RaysAreTheStrataCentres) {
  const Camera c = telescope(16);
  StarPixel p;
  p.x = 3;
  p.y = 5;
  p.side = 4;
  Vec3 o, d, o0, d0;
  c.ray_through(3.125f, 5.125f, o0, d0);
  ASSERT_TRUE(star_pixel_ray(c, p, 0, o, d));
  EXPECT_NEAR(o.x, o0.x, 1e-6);
  EXPECT_NEAR(o.y, o0.y, 1e-6);
  c.ray_through(3.875f, 5.375f, o0, d0);
  ASSERT_TRUE(star_pixel_ray(c, p, 4 + 3, o, d));  // row 1, column 3
  EXPECT_NEAR(o.x, o0.x, 1e-6);
  EXPECT_NEAR(o.y, o0.y, 1e-6);
  const RayFootprint f = sub_pixel_footprint(c.footprint(), 4);
  EXPECT_FLOAT_EQ(f.width(0.0f) * 4, c.footprint().width(0.0f));
}

}  // namespace
}  // namespace nebula
