#pragma once
// Statistics helpers for Monte-Carlo tests: tolerances come from estimated
// standard errors, never from tuning.
#include <cmath>

namespace nebula::test {

// z-score of the difference of two independent estimates.
inline double z_score(double a, double sa, double b, double sb) {
  const double s = std::sqrt(sa * sa + sb * sb);
  return s > 0 ? (a - b) / s : (a == b ? 0.0 : INFINITY);
}

}  // namespace nebula::test
