#include "illumination/chord_irradiance.h"

#include <gtest/gtest.h>

#include <cmath>

namespace nebula {
namespace {

// The mean of 1 / (b^2 + soft2 + s^2) over the chord by the midpoint rule on 20000 pieces.
double quadrature(Vec3 origin, Vec3 dir, double t0, double t1, Vec3 star, float soft2) {
  const int n = 20000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + (i + 0.5) * (t1 - t0) / n;
    const Vec3 p = origin + float(t) * dir;
    const Vec3 d = p - star;
    sum += 1.0 / (double(dot(d, d)) + soft2);
  }
  return sum / n;
}

TEST(ChordIrradiance, IsTheMeanOfTheInverseSquareOverTheChordNearAndFar) {
  const Vec3 origin{0, 0, -5}, dir{0, 0, 1}, star{0.02f, -0.01f, 0.013f};
  const RayFootprint footprint{0.0f, 0.001f};
  // The pixel's b^2 less the ray's: what the line's distance is softened by.
  const Vec3 off{star.x, star.y, 0};
  const float soft2 = pixel_mean_b2(off, footprint.width(5.013f), footprint) - dot(off, off);
  // Chords through the star, beside it, and far away (the cheap branch).
  const float chords[][2] = {{4.9f, 5.1f}, {4.99f, 5.0f}, {5.0f, 5.03f}, {3.0f, 3.05f}, {6.0f, 6.01f}, {1.0f, 9.0f}};
  for (const auto& c : chords) {
    const ChordIrradiance e = chord_irradiance(origin, dir, c[0], c[1], star, footprint);
    const double want = quadrature(origin, dir, c[0], c[1], star, soft2);
    EXPECT_NEAR(e.inv_r2 / want, 1.0, 2e-3) << "chord " << c[0] << ".." << c[1];
    // Half of the chord's light is received before the point.
    const float tp = dot(e.point - origin, dir);
    ASSERT_GE(tp, c[0]);
    ASSERT_LE(tp, c[1]);
    const double before = quadrature(origin, dir, c[0], tp, star, soft2) * (tp - c[0]);
    EXPECT_NEAR(before / (want * (c[1] - c[0])), 0.5, 0.02) << "chord " << c[0] << ".." << c[1];
  }
}

// The mean of 1 / |(x, y) + (u, v)| over the unit square by the midpoint rule,
// n x n pieces (the integrand's cusp, where the square holds the origin, is
// integrable: the rule converges as 1 / n).
double square_quadrature(double x, double y, int n) {
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = x - 0.5 + (i + 0.5) / n, v = y - 0.5 + (j + 0.5) / n;
      sum += 1.0 / std::hypot(u, v);
    }
  return sum / (double(n) * n);
}

TEST(PixelMean, IsTheMeanOfTheInverseDistanceOverTheSquarePixel) {
  // Centre, corner, edge, inside, beside and far from the pixel; both signs.
  const double offsets[][2] = {{0, 0},    {0.5, 0.5}, {-0.5, 0.5}, {0.5, 0},  {0.2, -0.35},
                               {1.3, 0.4}, {-2.1, -1.7}, {3.9, 0.2}, {0, -4.5}};
  for (const auto& o : offsets) {
    const double want = square_quadrature(o[0], o[1], 2000);
    const double got = square_pixel_mean_inverse_distance(float(o[0]), float(o[1]));
    // The quadrature's own error near the cusp is below 1e-3 at 2000 x 2000.
    EXPECT_NEAR(got / want, 1.0, 1e-3) << o[0] << ", " << o[1];
  }
  // The closed forms at the centre and the corner: 4 asinh(1) and 2 asinh(1).
  EXPECT_NEAR(square_pixel_mean_inverse_distance(0, 0), 4 * std::asinh(1.0), 1e-5);
  EXPECT_NEAR(square_pixel_mean_inverse_distance(0.5f, -0.5f), 2 * std::asinh(1.0), 1e-5);
}

TEST(PixelMean, ItsSquaredDistanceIsContinuousAndTendsToBSquared) {
  RayFootprint f{0.0f, 0.001f, {1, 0, 0}, {0, 1, 0}};
  const float w = 0.002f;
  // Across the switch to b^2 - w^2 / 12 at 4 widths, along an axis and a diagonal.
  for (const Vec3 dir : {Vec3{1, 0, 0}, Vec3{0.6f, 0.8f, 0}}) {
    const float inside = pixel_mean_b2(3.9999f * w * dir, w, f), outside = pixel_mean_b2(4.0001f * w * dir, w, f);
    EXPECT_NEAR(inside / outside, 1.0, 2e-4) << dir.x;
  }
  const Vec3 far{0.5f, 0.0f, 0};
  EXPECT_NEAR(pixel_mean_b2(far, w, f) / dot(far, far), 1.0, 1e-5);
  // On the star's line: 1 / (4 asinh 1)^2 of w^2; without sides (a fisheye), the round pixel's w^2 / (4 pi).
  EXPECT_NEAR(pixel_mean_b2({}, w, f) / (w * w), 1.0 / std::pow(4 * std::asinh(1.0), 2), 1e-5);
  const RayFootprint round{0.0f, 0.001f};
  EXPECT_NEAR(pixel_mean_b2({}, w, round) / (w * w), 1.0 / (4 * kPiD), 1e-6);
}

// The star at whose image a ray passes, taken once per ray (near_star), gives
// every chord the same numbers as the per-chord form, for it and the others.
TEST(ChordIrradiance, TheImagesStarOncePerRayEqualsThePerChordForm) {
  struct Star {
    Vec3 position;
  };
  const RayFootprint f{0.0f, 0.001f, {1, 0, 0}, {0, 1, 0}};
  const Vec3 origin{0, 0, -5}, dir{0, 0, 1};
  // Width at the stars (distance 5): 0.005. The second star within 4 widths
  // of the ray, the first and third beyond them.
  const Star stars[] = {{{0.3f, 0.1f, 0.0f}}, {{0.004f, -0.007f, 0.2f}}, {{0.012f, 0.02f, 0.4f}}};
  const NearStar near = near_star<true>(stars, 3, origin, dir, f);
  EXPECT_EQ(near.k, 1);
  EXPECT_TRUE(near.on_ray.closed_form);
  EXPECT_EQ(near_star<false>(stars, 3, origin, dir, f).k, -1);  // without kNearStar: none
  const float chords[][2] = {{4.0f, 4.9f}, {5.1f, 5.3f}, {5.19f, 5.21f}, {5.3f, 5.5f}};
  for (int k = 0; k < 3; ++k)
    for (const auto& c : chords) {
      const ChordIrradiance a = chord_irradiance<true>(near, k, stars[k].position, origin, dir, c[0], c[1], f);
      const ChordIrradiance b = chord_irradiance<true>(origin, dir, c[0], c[1], stars[k].position, f);
      EXPECT_EQ(a.inv_r2, b.inv_r2) << k;
      EXPECT_EQ(a.a0, b.a0) << k;
      EXPECT_EQ(a.a1, b.a1) << k;
      EXPECT_EQ(a.point.z, b.point.z) << k;
    }
  // A ray far from every image: none.
  EXPECT_EQ(near_star<true>(stars, 3, Vec3{1, 1, -5}, dir, f).k, -1);
}

TEST(ChordIrradiance, AStarOnTheRayOfAPointCameraStaysFinite) {
  const RayFootprint point_camera{};  // no width: the guard keeps b^2 above 0
  const ChordIrradiance e = chord_irradiance({0, 0, -1}, {0, 0, 1}, 0.5f, 1.5f, {0, 0, 0}, point_camera);
  EXPECT_TRUE(std::isfinite(e.inv_r2));
  EXPECT_GT(e.inv_r2, 0.0f);
  const ChordIrradiance p = point_irradiance({0, 0, 0}, {0, 0, 0}, 0.0f);
  EXPECT_TRUE(std::isfinite(p.inv_r2));
}

}  // namespace
}  // namespace nebula
