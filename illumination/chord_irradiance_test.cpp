#include "illumination/chord_irradiance.h"

#include <gtest/gtest.h>

#include <cmath>

namespace nebula {
namespace {

// The mean of 1 / (b^2 + w^2 / (4 pi) + s^2) over the chord by the midpoint rule on 20000 pieces.
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
  const float soft2 = std::pow(footprint.width(5.013f), 2.0f) * float(kInv4Pi);
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
