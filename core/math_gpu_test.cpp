// The device's fast functions (core/math.h) against double precision, within
// the bounds their comments state: the CUDA Programming Guide's table of
// intrinsic functions (reciprocal 2 ulp, reciprocal square root 2 ulp, e^x
// 2 + floor(1.173 |x|) ulp), over the ranges the marchers use.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/math_gpu.h"
#include "core/test_support.h"

namespace nebula {
namespace {

// The error in ulps as the CUDA guide counts it: the number of floats between
// the result and the correctly rounded one (same sign, finite).
double ulps(float got, double exact) {
  const float rounded = static_cast<float>(exact);
  if (got == rounded) return 0.0;
  if ((got < 0.0f) != (rounded < 0.0f) || !std::isfinite(got)) return 1e30;
  int32_t a, b;
  std::memcpy(&a, &got, 4);
  std::memcpy(&b, &rounded, 4);
  return std::fabs(double(a) - double(b));
}

std::vector<float> log_uniform(float lo, float hi, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  std::vector<float> x(n);
  for (float& v : x) v = static_cast<float>(std::exp(u(rng)));
  return x;
}

TEST(FastMathHost, IsTheLibrarysFunctions) {
  for (float x : {1e-20f, 0.3f, 1.0f, 7.5f, 1e20f}) {
    EXPECT_EQ(reciprocal(x), 1.0f / x);
    EXPECT_EQ(reciprocal_sqrt(x), 1.0f / std::sqrt(x));
  }
  for (float x : {-80.0f, -3.2f, -1e-6f, 0.0f}) EXPECT_EQ(fast_exp(x), std::exp(x));
}

TEST(FastMathGpu, ReciprocalWithinTwoUlp) {
  NEBULA_SKIP_WITHOUT_GPU();
  std::vector<float> x = log_uniform(1e-30f, 1e30f, 200000, 1);
  for (size_t i = 0; i < x.size(); i += 2) x[i] = -x[i];
  const std::vector<float> y = fast_math_gpu(FastMath::Reciprocal, x);
  double worst = 0;
  for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, ulps(y[i], 1.0 / double(x[i])));
  std::printf("reciprocal: worst %.0f ulp\n", worst);
  EXPECT_LE(worst, 2.0);
}

TEST(FastMathGpu, ReciprocalSqrtWithinTwoUlp) {
  NEBULA_SKIP_WITHOUT_GPU();
  const std::vector<float> x = log_uniform(1e-30f, 1e30f, 200000, 2);
  const std::vector<float> y = fast_math_gpu(FastMath::ReciprocalSqrt, x);
  double worst = 0;
  for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, ulps(y[i], 1.0 / std::sqrt(double(x[i]))));
  std::printf("reciprocal square root: worst %.0f ulp\n", worst);
  EXPECT_LE(worst, 2.0);
}

TEST(FastMathGpu, ExpWithinItsBoundAndExactAtZero) {
  NEBULA_SKIP_WITHOUT_GPU();
  // Attenuations e^-tau with results above the smallest normal float (tau < 87).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> tau(0.0f, 87.0f);
  std::vector<float> x(200000);
  for (float& v : x) v = -tau(rng);
  const std::vector<float> small = log_uniform(1e-8f, 1.0f, 50000, 4);
  for (float v : small) x.push_back(-v);
  x.push_back(0.0f);
  x.push_back(-0.0f);
  x.push_back(-200.0f);
  const std::vector<float> y = fast_math_gpu(FastMath::Exp, x);
  double worst_excess = -1e30;  // largest error less its bound, over the sample
  for (size_t i = 0; i + 3 < x.size(); ++i) {
    const double bound = 2.0 + std::floor(std::fabs(1.173 * double(x[i])));
    worst_excess = std::max(worst_excess, ulps(y[i], std::exp(double(x[i]))) - bound);
  }
  std::printf("e^x: worst error less its bound %.0f ulp\n", worst_excess);
  EXPECT_LE(worst_excess, 0.0);
  const size_t n = x.size();
  EXPECT_EQ(y[n - 3], 1.0f);  // exp(0) = 1 exactly: empty samples stay exact no-ops
  EXPECT_EQ(y[n - 2], 1.0f);
  EXPECT_GE(y[n - 1], 0.0f);  // deep attenuation: zero (flushed) or a subnormal, never NaN
  EXPECT_LT(y[n - 1], 1e-37f);
}

}  // namespace
}  // namespace nebula
