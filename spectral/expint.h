#pragma once
// Algorithm 1 of Barrès (2023), its appendix: integrals of lambda^k e^(-a/lambda)
// in closed form through the generalised exponential integral
//   E_m(x) = integral_1^inf e^(-x t) t^(-m) dt,  E_(m+1)(x) = (e^-x - x E_m(x)) / m,
// whose antiderivative rule is  d/dlambda [lambda^(k+1) E_(k+2)(a/lambda)] = lambda^k e^(-a/lambda).
// Negative powers (Wien's lambda^-5) take the substitution u = 1/lambda and the
// regularised incomplete gamma function instead. Everything is computed in
// scaled form (e^x E_m(x)) so that no term under- or overflows, and the small-
// and large-argument limits avoid the cancellations of the plain differences
// (docs/spectral.md gives the accuracy measured against quadrature).
// Double precision, host and device.
#include <cmath>

#include "core/hd.h"

namespace nebula::spectral {

constexpr double kEulerGamma = 0.57721566490153286061;

// e^x E_m(x) for m >= 1, x >= 0 (x = 0 only for m >= 2: E_m(0) = 1/(m-1)).
// Power series for x <= 1, Lentz's continued fraction above.
NEBULA_HD double scaled_expint(int m, double x) {
  if (x == 0.0) return 1.0 / (m - 1);
  if (x > 1.0) {
    // E_m(x) = e^-x (1/(x+m-) (1 m)/(x+m+2-) (2 (m+1))/(x+m+4-) ...)
    double b = x + m, c = 1e300, d = 1.0 / b, h = d;
    for (int i = 1; i < 400; ++i) {
      const double an = -double(i) * (m - 1 + i);
      b += 2.0;
      d = 1.0 / (an * d + b);
      c = b + an / c;
      const double del = c * d;
      h *= del;
      if (fabs(del - 1.0) < 1e-16) break;
    }
    return h;
  }
  // E_m(x) = (-x)^(m-1)/(m-1)! (psi(m) - ln x) - sum_{j != m-1} (-x)^j / ((j - m + 1) j!)
  double sum = m - 1 != 0 ? 1.0 / (m - 1) : -log(x) - kEulerGamma;
  double term = 1.0;  // (-x)^j / j!
  for (int j = 1; j < 200; ++j) {
    term *= -x / j;
    double add;
    if (j != m - 1) {
      add = -term / (j - m + 1);
    } else {
      double psi = -kEulerGamma;
      for (int i = 1; i < m; ++i) psi += 1.0 / i;
      add = term * (psi - log(x));
    }
    sum += add;
    if (fabs(add) < fabs(sum) * 1e-17) break;
  }
  return sum * exp(x);
}

// E_1(x1) - E_1(x2) for 0 < x1 <= x2, without the cancellation of two large
// logarithms at small x: ln(x2/x1) minus the difference of the power series.
NEBULA_HD double expint1_difference(double x1, double x2) {
  if (x2 > 1.0 || x1 > 0.5) {
    // e^-x2 [e^(x2-x1) Ê1(x1) - Ê1(x2)]; the factor is exact for x1 large.
    const double e1 = x1 > 0.0 ? scaled_expint(1, x1) : 0.0;
    return exp(-x1) * e1 - exp(-x2) * scaled_expint(1, x2);
  }
  double sum = log(x2 / x1);
  double t1 = 1.0, t2 = 1.0;
  for (int j = 1; j < 60; ++j) {
    t1 *= -x1 / j;
    t2 *= -x2 / j;
    sum += (t2 - t1) / j;  // -(-x)^j/(j j!) of E_1(x1) minus that of E_1(x2)
    if (fabs(t2) < 1e-18 * fabs(sum)) break;
  }
  return sum;
}

// P(n, x) / x^n for the regularised lower incomplete gamma P, integer n >= 1:
// e^-x sum_{j>=0} x^j / (n (n+1) ... (n+j)) / (n-1)! ... written as
// gamma(n, x) / ((n-1)! x^n) with the series gamma(n,x) = x^n e^-x sum x^j / (n)_(j+1).
NEBULA_HD double lower_gamma_over_power(int n, double x) {
  double term = 1.0 / n, sum = term;
  for (int j = 1; j < 500; ++j) {
    term *= x / (n + j);
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  double factorial = 1.0;
  for (int i = 2; i < n; ++i) factorial *= i;
  return exp(-x) * sum / factorial;
}

// e^x Q(n, x) = sum_{j<n} x^j / j!: the scaled regularised upper incomplete gamma, integer n.
NEBULA_HD double scaled_upper_gamma(int n, double x) {
  double term = 1.0, sum = 1.0;
  for (int j = 1; j < n; ++j) {
    term *= x / j;
    sum += term;
  }
  return sum;
}

// integral_{l1}^{l2} lambda^k e^(-a/lambda) d lambda, 0 < l1 <= l2, a >= 0, any integer k.
NEBULA_HD double power_exp_integral(int k, double a, double l1, double l2) {
  if (!(l2 > l1)) return 0.0;
  const double x1 = a / l2, x2 = a / l1;  // x1 <= x2
  if (k == -1) return a > 0.0 ? expint1_difference(x1, x2) : log(l2 / l1);
  if (k >= 0) {
    // lambda^(k+1) E_(k+2)(a/lambda) between the ends, factored by e^-x1.
    const int m = k + 2;
    const double hi = pow(l2, k + 1) * scaled_expint(m, x1);
    const double lo = pow(l1, k + 1) * scaled_expint(m, x2) * exp(-(x2 - x1));
    return exp(-x1) * (hi - lo);
  }
  // k <= -2: u = 1/lambda, integral_{1/l2}^{1/l1} u^n e^(-a u) du with n = -k-2 >= 0:
  // n! / a^(n+1) [P(n+1, x2) - P(n+1, x1)].
  const int n = -k - 2;
  double factorial = 1.0;
  for (int i = 2; i <= n; ++i) factorial *= i;
  const double u1 = 1.0 / l2, u2 = 1.0 / l1;
  if (x2 <= n + 2.0) {
    // Both small: P(n+1, x) = x^(n+1) p(x), so the a^-(n+1) cancels exactly.
    return factorial * (pow(u2, n + 1) * lower_gamma_over_power(n + 1, x2) -
                        pow(u1, n + 1) * lower_gamma_over_power(n + 1, x1));
  }
  // P(x2) - P(x1) = Q(x1) - Q(x2) = e^-x1 [q(x1) - e^-(x2-x1) q(x2)].
  return factorial / pow(a, n + 1) * exp(-x1) *
         (scaled_upper_gamma(n + 1, x1) - exp(-(x2 - x1)) * scaled_upper_gamma(n + 1, x2));
}

// Antiderivatives of lambda^k e^(-a/lambda) at one point b > 0, for every
// k = m - 2 with m in [m_lo, m_hi] (at most kMaxAntiderivatives): out[m - m_lo].
// Their differences between two points are power_exp_integral; a piecewise
// polynomial sum_k c_ik lambda^k on segments [b_i, b_(i+1)] integrates against
// e^(-a/lambda) as sum over its breaks b_j of sum_k (c_(j-1)k - c_jk) F_k(b_j)
// (c zero beyond the ends): one set of F per break, shared by every segment
// that meets there, every power and every filter with that break (Algorithm 1;
// docs/spectral.md, "The math"). Two conventions, which differ by a constant in
// b, so one sum must use one of them at all its breaks:
//   series (for a / b <= 1 at every break, a = 0 included):
//     F_k(b) = sum_n (-a)^n / n! A_(k-n)(b), A_q = b^(q+1) / (q+1), A_-1 = ln b,
//     i.e. b^(k+1) sum_n (-x)^n / n! w_n, x = a / b, w_n = 1 / (k+1-n) or ln b;
//   exact (a > 0): F_k(b) = b^(k+1) E_(k+2)(a / b), E_m for m <= 0 as well
//     (E_m(x) = integral_1^inf e^(-x t) t^(-m) dt; the recurrence
//     m E_(m+1) = e^-x - x E_m holds for all m).
// The exact form's E_m for m <= 0 grow as (-m)! / x^(1-m) at small x, a
// constant (-m)! / a^(1-m) in F that the sum cancels: the series avoids that
// cancellation where a is small.
constexpr int kMaxAntiderivatives = 8;
constexpr int kMaxTaylorTerms = 28;

// b^n for a small integer n by multiplications (pow costs ~20x more).
NEBULA_HD double integer_power(double b, int n) {
  double r = 1.0;
  const double f = n < 0 ? 1.0 / b : b;
  for (int i = n < 0 ? -n : n; i > 0; --i) r *= f;
  return r;
}

// e^x E_m(x) for m in [m_lo, top], top >= 1, x > 0: out[m - m_lo]. For x >= 1
// the highest order by its continued fraction and the recurrence downwards
// (stable there); below 1 E_1 by its series, upwards (stable for x < m) and
// downwards from E_0 = e^-x / x (all terms positive).
NEBULA_HD void scaled_expint_range(double x, int m_lo, int top, double* out) {
  const auto at = [&](int m) -> double& { return out[m - m_lo]; };
  if (x >= 1.0) {
    at(top) = scaled_expint(top, x);
    for (int m = top - 1; m >= m_lo; --m) at(m) = (1.0 - m * at(m + 1)) / x;
  } else if (m_lo <= 1) {
    at(1) = scaled_expint(1, x);
    for (int m = 0; m >= m_lo; --m) at(m) = (1.0 - m * at(m + 1)) / x;
    for (int m = 1; m < top; ++m) at(m + 1) = (1.0 - x * at(m)) / m;
  } else {  // m_lo >= 2: upwards from m_lo, itself by its series
    at(m_lo) = scaled_expint(m_lo, x);
    for (int m = m_lo; m < top; ++m) at(m + 1) = (1.0 - x * at(m)) / m;
  }
}

// The antiderivatives at ascending breaks for one a (closed_form in
// spectral_march.h): the exact convention steps from one break to the next by
// Taylor's series in x = a / b, E_m(x - h) = sum_n h^n / n! E_(m-n)(x) (since
// E_m' = -E_(m-1)), the lower orders by the downward recurrence (all terms
// positive); x falls by h = x (1 - b_prev / b), so the terms fall as
// (1 - b_prev / b)^n: a 10-nm step at 400 nm needs about 10 of them, where a
// fresh continued fraction would need dozens of divisions. A step of more than
// a quarter of x starts afresh. The series convention is evaluated per break.
struct AntiderivativeWalk {
  static constexpr int kSeriesTerms = 40;  // >= kMaxTaylorTerms
  static constexpr int kLowest = kMaxAntiderivatives + kSeriesTerms;  // inverse[q + kLowest] = 1 / q
  double a = 0;
  bool series = true;
  int m_lo = 0, m_hi = 0;
  double x = 0, decay = 0;  // the last break's a / b and e^-x
  double e[kMaxAntiderivatives + 2] = {};  // e^x E_m(x) there, m in [m_lo, m_hi] (beyond: unused)
  double inverse[kLowest + kMaxAntiderivatives] = {};  // series: 1 / q, q = k + 1 - n (ln b at q = 0)
  double inverse_n[kSeriesTerms + 1] = {};               // 1 / n: no division on the terms' chain
  bool started = false;

  NEBULA_HD AntiderivativeWalk(double a_, bool series_, int m_lo_, int m_hi_)
      : a(a_), series(series_), m_lo(m_lo_), m_hi(m_hi_) {
    if (series)
      for (int q = m_lo - kSeriesTerms; q < m_hi; ++q) inverse[q + kLowest] = q != 0 ? 1.0 / q : 0.0;
    for (int n = 1; n <= kSeriesTerms; ++n) inverse_n[n] = 1.0 / n;
  }

  NEBULA_HD void at(double b, double* out) {
    const int n_m = m_hi - m_lo + 1;
    if (series) {
      // The series convention (above): b^(k+1) sum_n (-x)^n / n! w_n, the 1 / q from the table.
      const double x_b = a / b;
      inverse[kLowest] = log(b);
      for (int i = 0; i < n_m; ++i) out[i] = 0.0;
      double t = 1.0;  // (-x)^n / n!
      for (int n = 0; n < kSeriesTerms; ++n) {
        for (int i = 0; i < n_m; ++i) out[i] += t * inverse[m_lo + i - 1 - n + kLowest];
        t *= -x_b * inverse_n[n + 1];
        if (fabs(t) < 1e-19) break;
      }
      double power = integer_power(b, m_lo - 1);
      for (int i = 0; i < n_m; ++i, power *= b) out[i] *= power;
      return;
    }
    const double x_new = a / b, h = x - x_new;
    if (!started || !(h >= 0.0) || h > 0.25 * x) {
      scaled_expint_range(x_new, m_lo, m_hi > 1 ? m_hi : 1, e);
      decay = exp(-x_new);
    } else {
      // v[kMaxTaylorTerms + m - m_lo] = e^x E_m(x) at the previous x: the orders the
      // walk keeps, extended downwards as the terms need them. All kMaxAntiderivatives
      // orders are summed (a fixed count: the loops unroll, the sums stay in registers);
      // those above m_hi are never read.
      const double inverse_x = 1.0 / x;
      double v[kMaxTaylorTerms + kMaxAntiderivatives];
      double* top = v + kMaxTaylorTerms;
      double sum[kMaxAntiderivatives];
      NEBULA_UNROLL
      for (int i = 0; i < kMaxAntiderivatives; ++i) top[i] = sum[i] = e[i];
      const double tolerance = 1e-17 * e[n_m - 1];
      double hn = 1.0;  // h^n / n!
      for (int n = 1; n <= kMaxTaylorTerms; ++n) {
        hn *= h * inverse_n[n];
        top[-n] = (1.0 - (m_lo - n) * top[1 - n]) * inverse_x;
        const double* from = top - n;
        NEBULA_UNROLL
        for (int i = 0; i < kMaxAntiderivatives; ++i) sum[i] += hn * from[i];
        if (hn * top[-n] < tolerance) break;
      }
      const double step = exp(-h);
      NEBULA_UNROLL
      for (int i = 0; i < kMaxAntiderivatives; ++i) e[i] = sum[i] * step;
      decay /= step;
    }
    x = x_new;
    started = true;
    double power = integer_power(b, m_lo - 1) * decay;
    for (int i = 0; i < n_m; ++i, power *= b) out[i] = power * e[i];
  }
};

// The antiderivatives at one point (the walk's first step).
NEBULA_HD void power_exp_antiderivatives(double a, double b, bool series, int m_lo, int m_hi, double* out) {
  AntiderivativeWalk walk(a, series, m_lo, m_hi);
  walk.at(b, out);
}

}  // namespace nebula::spectral
