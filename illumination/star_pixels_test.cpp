#include "illumination/star_pixels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
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
// it per axis, each once however many stars ask for it, cut into cells that
// tile it, finer towards the star; the cells' rays numbered one after another.
TEST(StarPixels, AreThePixelsAroundEachStarsImageOnce) {
  const Camera c = telescope(16);
  int rays = 0;
  // A star on the common corner of pixels 7 and 8 (image x, y = 8).
  std::vector<StarPixel> p = star_pixels(c, {{0, 0, 0}}, &rays);
  const ImagePoint star_at = *project_point(c, {0, 0, 0});
  std::map<std::pair<int, int>, std::vector<StarPixel>> by_pixel;
  int total = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const StarPixel& q = p[i];
    EXPECT_EQ(q.first, total);
    total += q.side * q.side;
    EXPECT_EQ(q.cells > 0, by_pixel.count({q.x, q.y}) == 0) << "a pixel's first cell holds its count";
    if (q.cells > 0) {
      EXPECT_LE(i + size_t(q.cells), p.size());
    }
    by_pixel[{q.x, q.y}].push_back(q);
  }
  EXPECT_EQ(rays, total);
  // Centres at 0.5, 1.5, 2.5 from the corner on each side: 6 x 6 pixels.
  ASSERT_EQ(by_pixel.size(), 36u);
  for (const auto& [xy, cells] : by_pixel) {
    const auto [x, y] = xy;
    EXPECT_GE(x, 5);
    EXPECT_LE(x, 10);
    EXPECT_EQ(cells.front().cells, int(cells.size()));
    double area = 0, finest = 1;
    for (const StarPixel& q : cells) {
      area += double(q.size) * q.size;
      finest = std::min(finest, double(q.size));
      EXPECT_GE(q.u, 0.0f);
      EXPECT_LE(q.u + q.size, 1.0f);
      EXPECT_GE(q.v, 0.0f);
      EXPECT_LE(q.v + q.size, 1.0f);
    }
    EXPECT_NEAR(area, 1.0, 1e-12) << x << ", " << y;  // the cells tile the pixel
    const double dx = std::max({x - star_at.x, 0.0, star_at.x - (x + 1)});
    const double dy = std::max({y - star_at.y, 0.0, star_at.y - (y + 1)});
    const double d = std::hypot(dx, dy);
    if (d < 1e-3) {
      // At the star's image: cut down to the finest cells at its corner.
      EXPECT_TRUE((x == 7 || x == 8) && (y == 7 || y == 8)) << x << ", " << y;
      EXPECT_FLOAT_EQ(float(finest), kStarCellFinest) << x << ", " << y;
    } else if (d >= kStarCellSplit) {
      // Left whole, its rays from its distance to the star's image.
      ASSERT_EQ(cells.size(), 1u) << x << ", " << y;
      EXPECT_EQ(cells[0].side, int(std::ceil(kStarPixelRays / (1 + d) - 1e-9))) << x << ", " << y;
    }
  }
  // Every ray finds its cell.
  for (int i = 0; i < rays; i += 37) {
    const StarPixel& q = p[size_t(star_pixel_of_ray(p.data(), int(p.size()), i))];
    EXPECT_LE(q.first, i);
    EXPECT_LT(i, q.first + q.side * q.side);
  }
  // Two stars a pixel apart share pixels, each once, cut towards both.
  p = star_pixels(c, {{0, 0, 0}, {0.125f, 0, 0}}, &rays);
  std::set<std::pair<int, int>> seen;
  for (const StarPixel& q : p)
    if (q.cells > 0) {
      EXPECT_TRUE(seen.insert({q.x, q.y}).second) << q.x << ", " << q.y;
    }
  EXPECT_EQ(seen.size(), 42u);  // x from 5 to 11
  // A star outside the frame near its edge keeps the pixels inside; one behind the camera has none.
  const Vec3 edge{1.05f, 0, 0};
  const double at = project_point(c, edge)->x;  // 0.4 outside the frame
  p = star_pixels(c, {edge}, &rays);
  seen.clear();
  for (const StarPixel& q : p) {
    seen.insert({q.x, q.y});
    EXPECT_LE(std::fabs(q.x + 0.5 - at), kStarPixelReach);
  }
  EXPECT_EQ(seen.size(), 18u);  // 3 columns x 6 rows
  EXPECT_TRUE(star_pixels(c, {{0, 0, -20}}, &rays).empty());
  EXPECT_EQ(rays, 0);
}

// The rays of a cell are its strata's centres; a ray is narrower than its
// pixel by its cell's rays per side over the cell's size.
TEST(StarPixels, RaysAreTheStrataCentres) {
  const Camera c = telescope(16);
  StarPixel p;
  p.x = 3;
  p.y = 5;
  p.u = 0.5f;
  p.v = 0.25f;
  p.size = 0.25f;
  p.side = 4;
  Vec3 o, d, o0, d0;
  c.ray_through(3.5f + 0.03125f, 5.25f + 0.03125f, o0, d0);
  ASSERT_TRUE(star_pixel_ray(c, p, 0, o, d));
  EXPECT_NEAR(o.x, o0.x, 1e-6);
  EXPECT_NEAR(o.y, o0.y, 1e-6);
  c.ray_through(3.5f + 0.21875f, 5.25f + 0.09375f, o0, d0);
  ASSERT_TRUE(star_pixel_ray(c, p, 4 + 3, o, d));  // row 1, column 3
  EXPECT_NEAR(o.x, o0.x, 1e-6);
  EXPECT_NEAR(o.y, o0.y, 1e-6);
  EXPECT_FLOAT_EQ(star_pixel_narrowing(p), 16.0f);
  const RayFootprint f = sub_pixel_footprint(c.footprint(), star_pixel_narrowing(p));
  EXPECT_FLOAT_EQ(f.width(0.0f) * 16, c.footprint().width(0.0f));
}

// The cells are a quadrature of the pixel's area: a light profile with the
// 1/b cusp of a star's light and a peak narrower than a pixel, sampled at the
// cells' rays and stored as the marchers store them, gives each pixel its
// area's mean, where one ray per pixel misses it by tens of per cent. The
// reference: the midpoint rule on 2048 x 2048 points per pixel.
TEST(StarPixels, CellsIntegrateACuspOverEachPixel) {
  const Camera c = telescope(16);
  const double soft = 0.004;  // pixels: the cusp's softening, below the finest cell
  for (const Vec3 star : {Vec3{0, 0, 0}, Vec3{0.0625f, 0.0625f, 0}, Vec3{0.0301f, -0.0117f, 0}}) {
    const ImagePoint s = *project_point(c, star);
    auto light = [&](double x, double y) {
      const double b = std::hypot(x - s.x, y - s.y);
      return (1.0 + 3.0 / (1.0 + (b / 0.1) * (b / 0.1))) / std::sqrt(b * b + soft * soft);
    };
    int rays = 0;
    const std::vector<StarPixel> cells = star_pixels(c, {star}, &rays);
    std::vector<float> sub(static_cast<size_t>(rays));
    for (int i = 0; i < rays; ++i) {
      const StarPixel& q = cells[size_t(star_pixel_of_ray(cells.data(), int(cells.size()), i))];
      const int k = i - q.first;
      const double step = double(q.size) / q.side;
      sub[size_t(i)] = float(light(q.x + q.u + (k % q.side + 0.5) * step, q.y + q.v + (k / q.side + 0.5) * step));
    }
    std::vector<float> image(size_t(c.width) * c.height, 0.0f);
    for (int i = 0; i < int(cells.size()); ++i) reduce_star_cell(sub.data(), size_t(rays), cells.data(), i, 0);
    for (int i = 0; i < int(cells.size()); ++i)
      store_star_pixel(sub.data(), size_t(rays), cells.data(), i, 0, 1.0f, image.data(), c.width, c.height);
    double worst = 0, worst_one_ray = 0;
    for (const StarPixel& q : cells) {
      if (q.cells == 0) continue;
      const int n = 2048;
      double mean = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) mean += light(q.x + (i + 0.5) / n, q.y + (j + 0.5) / n);
      mean /= double(n) * n;
      worst = std::max(worst, std::fabs(image[size_t(q.y) * c.width + q.x] / mean - 1));
      worst_one_ray = std::max(worst_one_ray, std::fabs(light(q.x + 0.5, q.y + 0.5) / mean - 1));
    }
    EXPECT_LT(worst, 0.005) << "star at image " << s.x << ", " << s.y;
    EXPECT_GT(worst_one_ray, 0.2) << "star at image " << s.x << ", " << s.y;
    std::printf("star at image (%.3f, %.3f): %d rays, largest pixel error %.3f%% (one ray per pixel %.0f%%)\n", s.x,
                s.y, rays, 100 * worst, 100 * worst_one_ray);
  }
}

}  // namespace
}  // namespace nebula
