#pragma once
// Statistics helpers for Monte-Carlo tests: tolerances come from estimated
// standard errors, never from tuning.
#include <cmath>

namespace nebula::test {

// Upper critical value of chi-square with k degrees of freedom at the
// one-sided standard-normal quantile z (Wilson & Hilferty 1931 approximation,
// accurate to a few tenths of a percent for k >= 10).
inline double chi_square_critical(int k, double z) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + z * std::sqrt(a);
  return k * c * c * c;
}

// z-score of the difference of two independent estimates.
inline double z_score(double a, double sa, double b, double sb) {
  const double s = std::sqrt(sa * sa + sb * sb);
  return s > 0 ? (a - b) / s : (a == b ? 0.0 : INFINITY);
}

}  // namespace nebula::test
