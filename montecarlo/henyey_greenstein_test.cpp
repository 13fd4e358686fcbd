#include "montecarlo/henyey_greenstein.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/philox.h"

namespace nebula {
namespace {

// Composite Simpson rule on [a, b] with n (even) intervals.
template <class F>
double simpson(F f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * f(a + i * h);
  return s * h / 3;
}

TEST(HenyeyGreenstein, PhaseIsNormalisedAndMatchesDouble) {
  for (double g : {-0.9, -0.3, 0.0, 0.6, 0.9}) {
    const double integral =
        2 * kPiD * simpson([g](double mu) { return hg_phase_double(g, mu); }, -1, 1, 20000);
    EXPECT_NEAR(integral, 1.0, 1e-6) << "g=" << g;
    for (double mu : {-1.0, -0.5, 0.0, 0.7, 1.0})
      EXPECT_NEAR(hg_phase(float(g), float(mu)) / hg_phase_double(g, mu), 1.0, 1e-5);
  }
}

TEST(HenyeyGreenstein, CdfIsTheIntegralOfThePhaseFunction) {
  for (double g : {-0.9, -0.3, 1e-4, 0.6, 0.95}) {
    for (double mu : {-0.8, 0.0, 0.5, 0.99}) {
      const double integral =
          2 * kPiD * simpson([g](double m) { return hg_phase_double(g, m); }, -1, mu, 40000);
      EXPECT_NEAR(hg_cdf(g, mu), integral, 1e-7) << "g=" << g << " mu=" << mu;
    }
    EXPECT_NEAR(hg_cdf(g, -1), 0.0, 1e-12);
    EXPECT_NEAR(hg_cdf(g, 1), 1.0, 1e-12);
  }
}

TEST(HenyeyGreenstein, NegativeAsymmetryIsNotIsotropic) {
  // <mu> = g for HG; a sampler that tested g (not |g|) against the isotropic
  // threshold would return 0 for every negative g.
  for (double g : {-0.9, -0.3, 0.3}) {
    const int n = 400000;
    double sum = 0, sum2 = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const float mu = hg_sample(float(g), philox_uniform4(5, 0, i, 0, 0).u0).cos_theta;
      sum += mu;
      sum2 += double(mu) * mu;
    }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / (n - 1));
    EXPECT_NEAR(mean, g, 4 * se) << "g=" << g;
  }
}

TEST(HenyeyGreenstein, EndPointsAndExtremeAsymmetryStayFinite) {
  const float xis[] = {u32_to_open_unit(0), 0.5f, u32_to_open_unit(0xffffffffu)};
  for (float g : {-0.999999f, -0.99f, -1e-4f, 0.0f, 1e-4f, 0.5f, 0.99f, 0.999999f}) {
    for (float xi : xis) {
      const HgSample a = hg_sample(g, xi);
      EXPECT_TRUE(std::isfinite(a.cos_theta) && std::isfinite(a.sin_theta));
      EXPECT_GE(a.cos_theta, -1.0f);
      EXPECT_LE(a.cos_theta, 1.0f);
      EXPECT_GE(a.sin_theta, 0.0f);
      EXPECT_NEAR(a.cos_theta * a.cos_theta + a.sin_theta * a.sin_theta, 1.0f, 1e-6f);
      EXPECT_TRUE(std::isfinite(hg_phase(g, a.cos_theta)));
    }
  }
}

TEST(HenyeyGreenstein, ScatterDirectionKeepsUnitLengthAndAngle) {
  const Vec3 starts[] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, normalize({1e-7f, 0, 1})};
  for (Vec3 d : starts) {
    for (uint32_t i = 0; i < 2000; ++i) {
      const Uniform4 u = philox_uniform4(11, 0, i, 0, 0);
      const float mu = 2 * u.u0 - 1;
      float sp, cp;
      sin_cos_2pi(u.u1, sp, cp);
      const Vec3 out = scatter_direction(d, {mu, std::sqrt(1 - mu * mu)}, sp, cp);
      EXPECT_NEAR(length(out), 1.0f, 1e-6f);
      EXPECT_NEAR(dot(out, d), mu, 2e-6f);
    }
  }
  // The azimuth is uniform: around +z the mean of x and y vanish.
  double sx = 0, sy = 0;
  const int n = 100000;
  for (uint32_t i = 0; i < n; ++i) {
    const Uniform4 u = philox_uniform4(12, 0, i, 0, 0);
    float sp, cp;
    sin_cos_2pi(u.u1, sp, cp);
    const Vec3 out = scatter_direction({0, 0, 1}, {0.0f, 1.0f}, sp, cp);
    sx += out.x;
    sy += out.y;
  }
  // Var(cos phi) = 1/2 per sample.
  EXPECT_NEAR(sx / n, 0.0, 4 * std::sqrt(0.5 / n));
  EXPECT_NEAR(sy / n, 0.0, 4 * std::sqrt(0.5 / n));
}

}  // namespace
}  // namespace nebula
