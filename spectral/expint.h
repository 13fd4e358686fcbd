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

}  // namespace nebula::spectral
