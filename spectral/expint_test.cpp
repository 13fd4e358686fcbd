// Algorithm 1 (spectral/expint.h) against numerical quadrature over the whole
// parameter range: powers -7..6 (Wien's lambda^-5 among them), optical paths a
// from 0 through tiny (small-argument limit, where E_1 and the negative-power
// forms cancel) to a/lambda ~ 700 (large-argument limit, near underflow), on
// wide and narrow intervals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

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

// The antiderivatives at single points (power_exp_antiderivatives): their
// difference between an interval's ends is the integral, in the convention the
// marcher picks (series where a / lambda <= 1 at the interval's start, else
// exact), for every power the marcher asks (m = k + 2 in -2..5) and the same
// range of a as above.
TEST(Expint, AntiderivativesDifferToTheIntegral) {
  const double as[] = {0.0, 1e-12, 1e-6, 1e-3, 0.05, 0.3, 0.9, 1.0, 1.1, 2.5, 7.0, 30.0, 200.0};
  const double intervals[][2] = {{0.25, 1.0}, {0.3, 0.31}, {0.5, 0.5005}, {1.0, 10.0}, {0.36, 0.9}};
  constexpr int m_lo = -2, m_hi = 5;
  double worst = 0;
  int cases = 0;
  for (double a : as)
    for (const auto& iv : intervals) {
      if (a / iv[0] > 700.0) continue;
      const bool series = !(a / iv[0] > 1.0);
      double F1[kMaxAntiderivatives], F2[kMaxAntiderivatives];
      power_exp_antiderivatives(a, iv[0], series, m_lo, m_hi, F1);
      power_exp_antiderivatives(a, iv[1], series, m_lo, m_hi, F2);
      for (int m = m_lo; m <= m_hi; ++m) {
        const int k = m - 2;
        const long double ref = quadrature(k, a, iv[0], iv[1]);
        const double got = F2[m - m_lo] - F1[m - m_lo];
        const double rel = double(std::fabs((got - ref) / ref));
        worst = std::max(worst, rel);
        ++cases;
        EXPECT_LT(rel, 1e-9) << "k " << k << " a " << a << " [" << iv[0] << ", " << iv[1] << "] "
                             << (series ? "series" : "exact") << ": " << got << " vs " << double(ref);
      }
    }
  std::printf("  %d cases, largest relative error %.2e\n", cases, worst);
}

// A piecewise cubic in global powers of lambda integrated through the jumps of
// its coefficients at the breaks, the antiderivatives walked from break to
// break as the marcher does, equals the sum of its segments' integrals, for a
// discontinuous random one on 40 uneven breaks (steps of 1-4% in lambda).
TEST(Expint, SumOverBreaksIsThePiecewiseIntegral) {
  std::vector<double> breaks{0.36};
  for (int j = 1; j <= 40; ++j) breaks.push_back(breaks.back() + 0.004 + 0.012 * std::fabs(std::sin(7.3 * j)));
  const int S = int(breaks.size()) - 1;
  std::vector<double> c(size_t(S) * 4);
  for (int seg = 0; seg < S; ++seg) {  // a cubic near 1 on its segment, expanded to global powers
    const double mid = 0.5 * (breaks[seg] + breaks[seg + 1]);
    const double d[4] = {1.0 + 0.3 * std::sin(seg), 2.0 * std::cos(3.0 * seg), -40.0, 900.0 * std::sin(seg * 1.7)};
    // sum_j d_j (lambda - mid)^j
    c[seg * 4 + 0] = d[0] - d[1] * mid + d[2] * mid * mid - d[3] * mid * mid * mid;
    c[seg * 4 + 1] = d[1] - 2 * d[2] * mid + 3 * d[3] * mid * mid;
    c[seg * 4 + 2] = d[2] - 3 * d[3] * mid;
    c[seg * 4 + 3] = d[3];
  }
  for (double a : {0.0, 1e-5, 0.2, 0.36, 0.5, 3.0, 40.0})
    for (int p = -1; p <= 2; ++p) {  // the integrand lambda^(k - 1 - p): the marcher's offsets m = k + 1 - p
      const bool series = !(a / breaks[0] > 1.0);
      const int m_lo = 1 - p;
      double total = 0.0, reference = 0.0;
      for (int seg = 0; seg < S; ++seg)
        for (int k = 0; k < 4; ++k) reference += c[seg * 4 + k] * power_exp_integral(k - 1 - p, a, breaks[seg], breaks[seg + 1]);
      AntiderivativeWalk walk(a, series, m_lo, m_lo + 3);
      for (int j = 0; j <= S; ++j) {
        double F[kMaxAntiderivatives];
        walk.at(breaks[j], F);  // the marcher's way: each break's from the previous one's
        for (int k = 0; k < 4; ++k) {
          const double jump = (j > 0 ? c[(j - 1) * 4 + k] : 0.0) - (j < S ? c[j * 4 + k] : 0.0);
          total += jump * F[k];
        }
      }
      EXPECT_NEAR(total, reference, 1e-9 * std::fabs(reference)) << "a " << a << " p " << p;
      // And the walk's values at the last break equal a fresh evaluation there.
      double fresh[kMaxAntiderivatives], walked[kMaxAntiderivatives];
      power_exp_antiderivatives(a, breaks[S], series, m_lo, m_lo + 3, fresh);
      AntiderivativeWalk again(a, series, m_lo, m_lo + 3);
      for (int j = 0; j <= S; ++j) again.at(breaks[j], walked);
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(walked[k], fresh[k], 1e-12 * std::fabs(fresh[k])) << "a " << a << " k " << k;
    }
}

}  // namespace
}  // namespace nebula::spectral
