#pragma once
// Quadrature for the diffuse tests' references.
#include <cmath>
#include <vector>

#include "core/math.h"

namespace nebula::testing {

// Gauss-Legendre nodes and weights on [a, b] (Newton on P_n).
inline void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w) {
  x.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPiD * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::fabs(dz) < 1e-15) break;
    }
    x[i] = 0.5 * (a + b) + 0.5 * (b - a) * z;
    w[i] = (b - a) / ((1 - z * z) * dp * dp);
  }
}

}  // namespace nebula::testing
