#include "core/vec3.h"

#include <gtest/gtest.h>

#include "core/angular_binning.h"
#include "core/philox.h"

namespace nebula {
namespace {

TEST(OrthonormalFrame, OrthonormalEverywhereIncludingPoles) {
  const Vec3 poles[] = {{0, 0, 1}, {0, 0, -1}, {0, 1e-7f, -1}, {1e-7f, 0, 1}};
  for (Vec3 n : poles) {
    n = normalize(n);
    Vec3 t, b;
    orthonormal_frame(n, t, b);
    EXPECT_NEAR(dot(t, t), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(b, b), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(t, b), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(t, n), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(b, n), 0.0f, 1e-6f);
  }
  for (uint32_t i = 0; i < 10000; ++i) {
    const Uniform4 u = philox_uniform4(7, 0, i, 0, 0);
    const float z = 2 * u.u0 - 1, phi = 2 * kPi * u.u1, s = std::sqrt(1 - z * z);
    const Vec3 n = {s * std::cos(phi), s * std::sin(phi), z};
    Vec3 t, b;
    orthonormal_frame(n, t, b);
    const Vec3 c = cross(t, b);  // right-handed: t x b = n
    EXPECT_NEAR(dot(c, n), 1.0f, 1e-5f);
  }
}

TEST(AngularBins, EdgesCentresAndSolidAngles) {
  for (AngularBinning kind : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const AngularBins bins{kind, 36};
    double total = 0;
    for (int k = 0; k < bins.n; ++k) {
      EXPECT_LT(bins.edge(k), bins.edge(k + 1));
      EXPECT_GT(bins.centre(k), bins.edge(k));
      EXPECT_LT(bins.centre(k), bins.edge(k + 1));
      EXPECT_EQ(bins.bin_of(static_cast<float>(bins.centre(k))), k);
      total += bins.solid_angle(k);
    }
    EXPECT_NEAR(total, 4 * kPiD, 1e-12);
    EXPECT_EQ(bins.bin_of(-1.0f), 0);
    EXPECT_EQ(bins.bin_of(1.0f), bins.n - 1);
    EXPECT_EQ(bins.bin_of(1.5f), bins.n - 1);  // clamped, never out of range
  }
}

}  // namespace
}  // namespace nebula
