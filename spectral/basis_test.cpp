// Algorithm 2 on the report's settings (Barrès 2023, Figs. 4.1-4.4): the
// family e^(-a/lambda), a in [0, 1], on [0.25, 1] um (where its 1/lambda law
// holds, Barrès: lambda > 0.25 um) and on [1, 10] um.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "spectral/basis.h"

namespace nebula::spectral {
namespace {

GreedyBasis report_basis(double lo, double hi, int n, std::vector<double>* a_values = nullptr) {
  const WavelengthGrid grid = WavelengthGrid::uniform(lo, hi, 2001);
  std::vector<std::vector<double>> family;
  for (int m = 0; m <= 100; ++m) {
    const double a = m / 100.0;
    if (a_values) a_values->push_back(a);
    std::vector<double> f;
    for (double l : grid.lambda) f.push_back(std::exp(-a / l));
    family.push_back(f);
  }
  return greedy_basis(grid, family, n, 0);
}

TEST(GreedyBasis, ErrorFallsMonotonicallyWithSize) {
  for (auto [lo, hi] : {std::pair{0.25, 1.0}, std::pair{1.0, 10.0}, std::pair{0.36, 0.9}}) {
    const GreedyBasis b = report_basis(lo, hi, 6);
    for (size_t n = 1; n < b.error.size(); ++n) {
      EXPECT_LT(b.error[n], b.error[n - 1]) << lo << "-" << hi << " um, " << n << " elements";
      // Every member's own error never rises either (projections on nested spans).
      for (size_t m = 0; m < b.member_error[n].size(); ++m)
        EXPECT_LE(b.member_error[n][m], b.member_error[n - 1][m] + 1e-12);
    }
    // The chosen elements are orthonormal.
    const WavelengthGrid grid = WavelengthGrid::uniform(lo, hi, 2001);
    for (int i = 0; i < b.size(); ++i)
      for (int j = 0; j < b.size(); ++j) EXPECT_NEAR(grid.dot(b.phi[i], b.phi[j]), i == j ? 1.0 : 0.0, 1e-9);
  }
}

// Beside the report's numbers (docs/spectral.md has the table): its best
// second element e^(-0.45/lambda) with largest error ~0.015 (Fig. 4.1-4.2),
// error /10 per element on [0, 1] um, /100 on [1, 10] um (Figs. 4.3-4.4).
TEST(GreedyBasis, ReportFigures) {
  std::vector<double> a;
  const GreedyBasis near = report_basis(0.25, 1.0, 5, &a);
  std::printf("  [0.25, 1] um: elements a =");
  for (int k : near.chosen) std::printf(" %.2f", a[size_t(k)]);
  std::printf("; largest error per size:");
  for (double e : near.error) std::printf(" %.2e", e);
  std::printf("\n");
  EXPECT_NEAR(a[size_t(near.chosen[1])], 0.45, 0.1);
  EXPECT_NEAR(near.error[2], 0.015, 0.005);
  const GreedyBasis far = report_basis(1.0, 10.0, 5);
  std::printf("  [1, 10] um: largest error per size:");
  for (double e : far.error) std::printf(" %.2e", e);
  std::printf("\n");
  for (int n = 2; n <= 4; ++n) EXPECT_GT(far.error[n] / far.error[n + 1], 20.0) << n;
}

TEST(GreedyBasis, RefusesSizeZero) {
  const WavelengthGrid grid = WavelengthGrid::uniform(0.3, 1.0, 11);
  EXPECT_THROW(greedy_basis(grid, {std::vector<double>(11, 1.0)}, 0), Error);
}

}  // namespace
}  // namespace nebula::spectral
