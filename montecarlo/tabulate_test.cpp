#include "montecarlo/tabulate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/error.h"
#include "core/math.h"
#include "montecarlo/henyey_greenstein.h"
#include "montecarlo/test_stats.h"

namespace nebula {
namespace {

TabulateParams small_params() {
  TabulateParams p;
  p.tau_max = 10;
  p.tau_bins = 11;
  p.mu_bins = 36;
  p.photons_per_row = 4000;
  return p;
}

// Thin limit: P(tau, mu) / tau -> p_HG(mu) (DESIGN.md; exact normalisation
// for the parallel beam), and 3/2 p_HG for the pencil beam, whose chord is the
// diameter 2R instead of the mean chord 4R/3. Bin means of p_HG are exact.
void expect_thin_limit(double g, Beam beam, double factor) {
  TabulateParams p;
  p.albedo = 0.6;
  p.g = g;
  p.tau_max = 1e-4;
  p.tau_bins = 2;
  p.mu_bins = 72;
  p.photons_per_row = 1000000;
  p.beam = beam;
  p.seed = 3;
  const Tabulation t = tabulate(p, Backend::Cpu);
  const double tau = t.tau[1];
  // First-order attenuation of light in and out of the sphere biases P/tau by
  // at most sigma_ext x (longest chord) = 2 R tau / a each way.
  const double bias = 2 * (2 * kVoxelSphereRadius * tau / p.albedo);
  const AngularBins bins = t.bins();
  for (int k = 0; k < p.mu_bins; ++k) {
    const double expected = factor * hg_bin_mean(g, bins.edge(k), bins.edge(k + 1));
    const double got = t.P[p.mu_bins + k] / tau;
    const double se = t.P_stderr[p.mu_bins + k] / tau;
    EXPECT_NEAR(got, expected, 4 * se + bias * expected)
        << "g=" << g << " bin " << k << " z=" << (got - expected) / se;
  }
}

// The parallel beam's thin limit for g in {-0.5, 0, 0.6, 0.9} is a case of
// validation/montecarlo_validation.cpp (validation_tests); here one g.
TEST(Tabulate, ThinLimitIsTheHgPhaseFunction) { expect_thin_limit(0.6, Beam::Parallel, 1.0); }

TEST(Tabulate, ThinLimitOfThePencilBeamIsThreeHalves) {
  expect_thin_limit(0.6, Beam::Pencil, 1.5);
}

TEST(Tabulate, ZeroDepthRowIsEmptyAndTotalsMatchP) {
  const TabulateParams p = small_params();
  const Tabulation t = tabulate(p, Backend::Cpu);
  const AngularBins bins = t.bins();
  for (int k = 0; k < p.mu_bins; ++k) EXPECT_EQ(t.P[k], 0.0);
  EXPECT_EQ(t.unscattered[0], 1.0);
  const double area = kPiD * kVoxelSphereRadius * kVoxelSphereRadius;
  for (int i = 0; i < p.tau_bins; ++i) {
    double sum = 0;
    for (int k = 0; k < p.mu_bins; ++k) sum += t.P[i * p.mu_bins + k] * bins.solid_angle(k) / area;
    EXPECT_NEAR(sum, t.total[i], 1e-12 + 1e-12 * t.total[i]);
    for (int k = 0; k < p.mu_bins; ++k) {
      EXPECT_TRUE(std::isfinite(t.P[i * p.mu_bins + k]));
      EXPECT_GE(t.P_stderr[i * p.mu_bins + k], 0.0);
    }
  }
}

TEST(Tabulate, SameSeedSameTableDifferentSeedDifferentTable) {
  TabulateParams p = small_params();
  const Tabulation a = tabulate(p, Backend::Cpu);
  const Tabulation b = tabulate(p, Backend::Cpu);
  EXPECT_EQ(a.P, b.P);
  EXPECT_EQ(a.P_stderr, b.P_stderr);
  EXPECT_EQ(a.scattering_events, b.scattering_events);
  p.seed = 2;
  const Tabulation c = tabulate(p, Backend::Cpu);
  EXPECT_NE(a.P, c.P);
}

// Forced first scattering and Russian roulette change the variance, not the
// expectation: the analog run agrees within 4 standard errors per entry.
TEST(Tabulate, VarianceReductionIsUnbiased) {
  TabulateParams p;
  p.tau_max = 2;
  p.tau_bins = 5;
  p.mu_bins = 24;
  p.photons_per_row = 200000;
  const Tabulation forced = tabulate(p, Backend::Cpu);
  p.forced_first_scattering = false;
  p.roulette.threshold = 0.05f;
  p.roulette.survival = 0.5f;
  p.seed = 99;
  const Tabulation analog = tabulate(p, Backend::Cpu);
  for (size_t e = p.mu_bins; e < forced.P.size(); ++e)
    EXPECT_LT(std::fabs(test::z_score(forced.P[e], forced.P_stderr[e], analog.P[e],
                                      analog.P_stderr[e])),
              4.0)
        << "entry " << e;
  for (int i = 1; i < p.tau_bins; ++i) {
    EXPECT_LT(std::fabs(test::z_score(forced.total[i], forced.total_stderr[i], analog.total[i],
                                      analog.total_stderr[i])),
              4.0);
    // The point of forcing: thin rows get much smaller errors for the same photons.
  }
  EXPECT_LT(forced.total_stderr[1], analog.total_stderr[1]);
}

// Rows of tau_sct < 1 trace photons_per_row x min(thin_boost, floor(1 / tau))
// photons, rows from tau_sct = 1 on photons_per_row: the same estimator with
// more photons, so the same expectation and a standard error smaller by the
// square root of the boost.
TEST(Tabulate, ThinRowsGetMorePhotons) {
  TabulateParams p;
  p.tau_max = 10;
  p.tau_bins = 1001;  // rows 0.01 apart
  p.photons_per_row = 1000;
  const std::pair<int, uint64_t> expected[] = {{0, 32}, {1, 32}, {3, 32}, {4, 25}, {5, 20}, {10, 10},
                                               {30, 3}, {99, 1}, {100, 1}, {1000, 1}};
  for (const auto& [row, boost] : expected) EXPECT_EQ(photons_of_row(p, row), 1000 * boost) << "row " << row;
  p.thin_boost = 1;
  EXPECT_EQ(photons_of_row(p, 1), 1000u);
  EXPECT_EQ(photons_of_table(p), 1001u * 1000u);

  // Row tau_sct = 0.1 (10 times the photons) against the same row without the boost.
  TabulateParams q;
  q.albedo = 0.6;
  q.g = 0.9;
  q.tau_max = 0.1;
  q.tau_bins = 2;
  q.mu_bins = 72;
  q.binning = AngularBinning::UniformTheta;
  q.photons_per_row = 20000;
  q.thin_boost = 1;
  const Tabulation plain = tabulate(q, Backend::Cpu);
  q.thin_boost = 32;
  q.seed = 2;  // independent photons
  const Tabulation boosted = tabulate(q, Backend::Cpu);
  // The standard errors are estimates too. A photon's tally X lies in [0, 2)
  // (weight / weight_scale, voxel_sphere.h), so its fourth central moment is at
  // most 4 sigma^2: the sample variance's relative spread is at most
  // 2 / (sigma sqrt(n)) and the standard error's half that, 1 / (n s_X) with
  // s_X = total_stderr / weight_scale the standard error of X's mean. The
  // ratio's logarithm then has a spread of at most the two in quadrature.
  auto spread = [](const Tabulation& t, const TabulateParams& p) {
    const double n = double(photons_of_row(p, 1));
    return 1.0 / (n * t.total_stderr[1] / weight_scale(p, 1));
  };
  TabulateParams q_plain = q;
  q_plain.thin_boost = 1;
  const double log_spread = std::hypot(spread(plain, q_plain), spread(boosted, q));
  const double ratio = plain.total_stderr[1] / boosted.total_stderr[1];
  std::printf("  stderr ratio %.3f (sqrt(10) = %.3f), its logarithm's spread at most %.3f\n", ratio, std::sqrt(10.0),
              log_spread);
  // The check below tells a boost of 10 from one of 5 (ln sqrt 2 apart), and from none.
  EXPECT_LT(4 * log_spread, 0.5 * std::log(2.0));
  EXPECT_LT(std::fabs(std::log(ratio / std::sqrt(10.0))), 4 * log_spread)
      << "the boosted row's standard error should be sqrt(10) times smaller";
  EXPECT_NEAR(boosted.total[1], plain.total[1], 4 * std::hypot(plain.total_stderr[1], boosted.total_stderr[1]));
  int beyond = 0;
  for (int k = 0; k < q.mu_bins; ++k) {
    const size_t e = size_t(q.mu_bins) + size_t(k);
    const double s = std::hypot(plain.P_stderr[e], boosted.P_stderr[e]);
    if (std::fabs(boosted.P[e] - plain.P[e]) > 4 * s) ++beyond;
  }
  EXPECT_LE(beyond, 1) << "bins beyond 4 standard errors of the unboosted row";
}

TEST(Tabulate, RefusesBadParametersNamingTheField) {
  // The field's name, never a command-line option: front ends reword it.
  auto parameter = [](TabulateParams p) {
    try {
      validate(p);
    } catch (const ParameterError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(e.parameter() + ": ", 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
      return e.parameter();
    }
    return std::string("accepted");
  };
  TabulateParams p;
  p.albedo = 1.5;
  EXPECT_EQ(parameter(p), "albedo");
  p = {};
  p.g = 1.0;
  EXPECT_EQ(parameter(p), "g");
  p.g = -1.0;
  EXPECT_EQ(parameter(p), "g");
  p = {};
  p.tau_max = 0;
  EXPECT_EQ(parameter(p), "tau_max");
  p = {};
  p.tau_bins = 1;
  EXPECT_EQ(parameter(p), "tau_bins");
  p = {};
  p.mu_bins = 1;
  EXPECT_EQ(parameter(p), "mu_bins");
  p = {};
  p.photons_per_row = 0;
  EXPECT_EQ(parameter(p), "photons_per_row");
  p = {};
  p.thin_boost = 0;
  EXPECT_EQ(parameter(p), "thin_boost");
  p.thin_boost = kMaxThinBoost + 1;
  EXPECT_EQ(parameter(p), "thin_boost");
  p = {};
  p.photons_per_row = kMaxBasePhotons + 1;  // too many in a thin row
  EXPECT_EQ(parameter(p), "photons_per_row");
  p.thin_boost = 1;
  EXPECT_EQ(parameter(p), "accepted");
  EXPECT_EQ(parameter(TabulateParams{}), "accepted");
}

TEST(Tabulate, ExtremeParametersStayFinite) {
  for (double g : {-0.99, 0.99}) {
    for (double a : {0.0, 1e-3, 1.0}) {
      TabulateParams p = small_params();
      p.g = g;
      p.albedo = a;
      p.tau_max = 50;
      p.photons_per_row = 500;
      const Tabulation t = tabulate(p, Backend::Cpu);
      for (double v : t.P) EXPECT_TRUE(std::isfinite(v) && v >= 0);
      for (int i = 0; i < p.tau_bins; ++i) {
        EXPECT_TRUE(std::isfinite(t.total[i]));
        EXPECT_LE(t.total[i] + t.unscattered[i], 1.0 + 1e-6);
      }
    }
  }
}

}  // namespace
}  // namespace nebula
