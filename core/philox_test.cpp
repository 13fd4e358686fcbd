#include "core/philox.h"

#include <gtest/gtest.h>

#include <cmath>

namespace nebula {
namespace {

// Known-answer vectors of Random123's kat_vectors file for philox4x32-10:
// counter (4 words), key (2 words) -> output (4 words).
TEST(Philox, KnownAnswerVectors) {
  struct Case {
    U32x4 ctr;
    uint32_t k0, k1;
    U32x4 want;
  };
  const Case cases[] = {
      {{0, 0, 0, 0}, 0, 0, {0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u}},
      {{0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu},
       0xffffffffu,
       0xffffffffu,
       {0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu}},
      {{0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u},
       0xa4093822u,
       0x299f31d0u,
       {0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u}},
  };
  for (const Case& c : cases) {
    const U32x4 got = philox4x32_10(c.ctr, c.k0, c.k1);
    EXPECT_EQ(got.v0, c.want.v0);
    EXPECT_EQ(got.v1, c.want.v1);
    EXPECT_EQ(got.v2, c.want.v2);
    EXPECT_EQ(got.v3, c.want.v3);
  }
}

TEST(Philox, OpenUnitIntervalNeverHitsEndPoints) {
  EXPECT_GT(u32_to_open_unit(0u), 0.0f);
  EXPECT_LT(u32_to_open_unit(0xffffffffu), 1.0f);
  EXPECT_TRUE(std::isfinite(std::log(u32_to_open_unit(0u))));
  EXPECT_TRUE(std::isfinite(std::log1p(-u32_to_open_unit(0xffffffffu))));
  // Symmetric about 1/2, so sampling with u or 1 - u is the same law.
  EXPECT_EQ(u32_to_open_unit(0u), 1.0f - u32_to_open_unit(0xffffffffu));
}

TEST(Philox, UniformMomentsAndIndependentStreams) {
  // Mean 1/2 and variance 1/12 within 4 standard errors; streams with
  // different stream words are uncorrelated.
  const int n = 200000;
  double sum = 0, sum2 = 0, cross = 0;
  for (int i = 0; i < n; ++i) {
    const Uniform4 a = philox_uniform4(42, 0, i, 0, 0);
    const Uniform4 b = philox_uniform4(42, 0, i, 1, 0);
    sum += a.u0;
    sum2 += a.u0 * a.u0;
    cross += (a.u1 - 0.5) * (b.u1 - 0.5);
  }
  const double mean = sum / n;
  const double var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 4 * std::sqrt(1.0 / 12 / n));
  // Var of the sample variance of U(0,1) is (1/80 - 1/144) / n.
  EXPECT_NEAR(var, 1.0 / 12, 4 * std::sqrt((1.0 / 80 - 1.0 / 144) / n));
  EXPECT_NEAR(cross / n, 0.0, 4 * (1.0 / 12) / std::sqrt(n));
}

}  // namespace
}  // namespace nebula
