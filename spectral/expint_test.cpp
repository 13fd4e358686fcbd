// Algorithm 1 (spectral/expint.h) against numerical quadrature over the whole
// parameter range: powers -7..6 (Wien's lambda^-5 among them), optical paths a
// from 0 through tiny (small-argument limit, where E_1 and the negative-power
// forms cancel) to a/lambda ~ 700 (large-argument limit, near underflow), on
// wide and narrow intervals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "spectral/expint.h"

namespace nebula::spectral {
namespace {

// Composite 5-point Gauss-Legendre in long double, 4000 panels: converged to
// ~1e-15 relative for these smooth integrands (checked by halving the panels).
long double quadrature(int k, double a, double l1, double l2, int panels = 4000) {
  static const long double x[5] = {-0.906179845938663992797626878299L, -0.538469310105683091036314420700L, 0.0L,
                                   0.538469310105683091036314420700L, 0.906179845938663992797626878299L};
  static const long double w[5] = {0.236926885056189087514264040720L, 0.478628670499366468041291514836L,
                                   0.568888888888888888888888888889L, 0.478628670499366468041291514836L,
                                   0.236926885056189087514264040720L};
  long double sum = 0;
  const long double h = (static_cast<long double>(l2) - l1) / panels;
  for (int p = 0; p < panels; ++p) {
    const long double m = l1 + (p + 0.5L) * h;
    for (int i = 0; i < 5; ++i) {
      const long double l = m + 0.5L * h * x[i];
      sum += w[i] * std::pow(l, (long double)k) * std::exp(-(long double)a / l);
    }
  }
  return sum * 0.5L * h;
}

TEST(Expint, ScaledExpintKnownValues) {
  // E_1(1) = 0.219383934395520, E_2(1) = 0.148495506775922 (Abramowitz & Stegun, Table 5.1).
  EXPECT_NEAR(scaled_expint(1, 1.0) * std::exp(-1.0), 0.219383934395520, 1e-14);
  EXPECT_NEAR(scaled_expint(2, 1.0) * std::exp(-1.0), 0.148495506775922, 1e-14);
  // The recurrence E_(m+1) = (e^-x - x E_m)/m holds on both branches (series <= 1 < fraction).
  for (double x : {1e-6, 0.3, 0.999, 1.001, 5.0, 80.0, 700.0})
    for (int m = 1; m < 9; ++m) {
      const double lhs = scaled_expint(m + 1, x), rhs = (1.0 - x * scaled_expint(m, x)) / m;
      EXPECT_NEAR(lhs, rhs, 1e-12 * std::fabs(lhs) + 1e-15) << "m " << m << " x " << x;
    }
}

TEST(Expint, PowerExpIntegralAgainstQuadratureEverywhere) {
  const double as[] = {0.0, 1e-12, 1e-8, 1e-4, 1e-2, 0.1, 0.45, 1.0, 3.0, 10.0, 30.0, 100.0, 200.0};
  const double intervals[][2] = {{0.25, 1.0}, {0.3, 0.31}, {0.5, 0.5005}, {1.0, 10.0}, {0.36, 0.9}};
  double worst = 0;
  int cases = 0;
  for (int k = -7; k <= 6; ++k)
    for (double a : as)
      for (const auto& iv : intervals) {
        if (a / iv[0] > 700.0) continue;  // e^-(a/lambda) underflows: no relative accuracy to ask for
        const long double ref = quadrature(k, a, iv[0], iv[1]);
        const double got = power_exp_integral(k, a, iv[0], iv[1]);
        const double rel = double(std::fabs((got - ref) / ref));
        worst = std::max(worst, rel);
        ++cases;
        EXPECT_LT(rel, 1e-9) << "k " << k << " a " << a << " [" << iv[0] << ", " << iv[1] << "]: " << got << " vs "
                             << double(ref);
      }
  std::printf("  %d cases, largest relative error %.2e\n", cases, worst);
}

TEST(Expint, LimitsBehave) {
  // a = 0: the plain power integral; k = -1 at tiny a: ln(l2/l1) (the E_1 difference cancels).
  EXPECT_NEAR(power_exp_integral(2, 0.0, 1.0, 2.0), 7.0 / 3.0, 1e-14);
  EXPECT_NEAR(power_exp_integral(-1, 1e-14, 1.0, 2.0), std::log(2.0), 1e-12);
  EXPECT_NEAR(power_exp_integral(-5, 0.0, 1.0, 2.0), (1.0 - 1.0 / 16.0) / 4.0, 1e-14);
  // Large a: positive, finite, no NaN, falls with a.
  double previous = 1e300;
  for (double a = 1.0; a < 2000.0; a *= 1.7) {
    const double v = power_exp_integral(-5, a, 0.3, 1.0);
    EXPECT_TRUE(std::isfinite(v));
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, previous);
    previous = v;
  }
}

}  // namespace
}  // namespace nebula::spectral
