#include "tables/table_lookup.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/error.h"
#include "core/placement.h"
#include "tables/scattering_table.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

using testing::make_test_table;

const float kInf = std::numeric_limits<float>::infinity();
const float kNaN = std::numeric_limits<float>::quiet_NaN();

// P = a + b tau + c u with u the bin index: linear in both lookup coordinates,
// so bilinear interpolation must reproduce it to float rounding everywhere.
constexpr double kA = 0.01, kB = 0.002, kC = 0.0005;

ScatteringTable make_linear_table(double tau_max, int n_tau, AngularBinning binning, int n_mu) {
  ScatteringTable t = ScatteringTable::make_axes(tau_max, n_tau, binning, n_mu);
  for (int i = 0; i < n_tau; ++i)
    for (int k = 0; k < n_mu; ++k) t.P[t.index(i, k)] = static_cast<float>(kA + kB * t.tau[i] + kC * k);
  return t;
}

TEST(TableLookup, ViewOfCopiesTheShape) {
  const ScatteringTable t = make_test_table(5.0, 11, AngularBinning::UniformTheta, 36);
  const TableView v = view_of(t);
  EXPECT_EQ(v.P, t.P.data());
  EXPECT_EQ(v.C, nullptr);  // the cumulative rows come with a placed view
  EXPECT_EQ(v.n_tau, 11);
  EXPECT_EQ(v.n_mu, 36);
  EXPECT_EQ(v.tau_max, 5.0f);
  EXPECT_EQ(v.bins.kind, AngularBinning::UniformTheta);
  EXPECT_EQ(v.bins.n, 36);
}

// A placed view is the same view with P wherever the placement put it: on the
// host (the CPU path) the table's own array.
TEST(TableLookup, PlacedViewKeepsTheShape) {
  const ScatteringTable t = make_test_table(5.0, 11, AngularBinning::UniformTheta, 36);
  HostPlacement host;
  const TableView v = place_table(t, host);
  EXPECT_EQ(v.P, t.P.data());
  EXPECT_NE(v.C, nullptr);
  EXPECT_EQ(v.n_tau, 11);
  EXPECT_EQ(v.n_mu, 36);
  EXPECT_EQ(host.bytes(), t.P.size() * sizeof(float));
}

// The mean over an interval of bin coordinates, from the cumulative rows in
// O(1), against a fine midpoint quadrature of the lookup itself: intervals
// inside, across the outermost centres and up to the domain's ends, at tau
// on and between rows; a tau beyond the table is clamped and counted once.
TEST(TableLookup, MeanOverAnglesIsTheMeanOfTheLookup) {
  const ScatteringTable t = make_test_table(5.0, 11, AngularBinning::UniformTheta, 36, 0.9);
  HostPlacement host;
  const TableView v = place_table(t, host);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u_of(-0.5f, 35.5f), tau_of(0.0f, 5.0f);
  double worst = 0;
  for (int trial = 0; trial < 300; ++trial) {
    float u0 = u_of(rng), u1 = u_of(rng);
    if (trial % 10 == 0) u0 = -0.5f;
    if (trial % 10 == 1) u1 = 35.5f;
    if (u0 > u1) std::swap(u0, u1);
    if (u1 - u0 < 1e-2f) continue;
    const float tau = trial % 3 == 0 ? 1.5f : tau_of(rng);
    const int n = 20000;
    double want = 0;
    for (int i = 0; i < n; ++i) want += v.lookup_at(tau, u0 + (i + 0.5f) * (u1 - u0) / n);
    want /= n;
    int clamped = 0;
    const double got = v.mean_over_angles(tau, u0, u1, &clamped);
    EXPECT_EQ(clamped, 0);
    worst = std::max(worst, std::fabs(got / want - 1));
  }
  EXPECT_LT(worst, 1e-4);
  int clamped = 0;
  EXPECT_NEAR(v.mean_over_angles(9.0f, 3.0f, 7.0f, &clamped), v.mean_over_angles(5.0f, 3.0f, 7.0f), 1e-6);
  EXPECT_EQ(clamped, 1);
}

TEST(TableLookup, ViewOfRefusesAMisshapenTable) {
  ScatteringTable t = make_test_table();
  t.P.pop_back();
  EXPECT_THROW(view_of(t), Error);
  ScatteringTable one_row = ScatteringTable::make_axes(1.0, 2, AngularBinning::UniformMu, 4);
  one_row.tau.resize(1);
  one_row.P.resize(4);
  EXPECT_THROW(view_of(one_row), Error);
}

// With dyadic axes (tau_i and the uniform-mu centres exact in float) the
// nodes come back bit for bit.
TEST(TableLookup, ReproducesGridValuesExactly) {
  const ScatteringTable t = make_test_table(4.0, 5, AngularBinning::UniformMu, 8);
  const TableView v = view_of(t);
  int clamped = 0;
  for (int i = 0; i < 5; ++i)
    for (int k = 0; k < 8; ++k)
      EXPECT_EQ(v.lookup(static_cast<float>(t.tau[i]), static_cast<float>(t.mu[k]), &clamped),
                t.P[t.index(i, k)])
          << "node " << i << ", " << k;
  EXPECT_EQ(clamped, 0);
}

// On realistic axes the nodes are reproduced to float rounding of the coordinates.
TEST(TableLookup, ReproducesGridValuesOnRealAxes) {
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const ScatteringTable t = make_test_table(10.0, 101, binning, 72);
    const TableView v = view_of(t);
    const float p_max = *std::max_element(t.P.begin(), t.P.end());
    for (int i = 0; i < t.n_tau(); i += 7)
      for (int k = 0; k < t.n_mu(); ++k)
        EXPECT_NEAR(v.lookup(static_cast<float>(t.tau[i]), static_cast<float>(t.mu[k])),
                    t.P[t.index(i, k)], 1e-5f * p_max)
            << to_string(binning) << " node " << i << ", " << k;
  }
}

TEST(TableLookup, MidpointsAreAverages) {
  const ScatteringTable t = make_test_table(4.0, 5, AngularBinning::UniformMu, 8);
  const TableView v = view_of(t);
  for (int i = 0; i + 1 < 5; ++i)
    for (int k = 0; k + 1 < 8; ++k) {
      const float tau_mid = static_cast<float>(0.5 * (t.tau[i] + t.tau[i + 1]));
      // Halfway between centres k and k + 1 lies edge k + 1 (uniform in mu).
      const float mu_mid = static_cast<float>(t.mu_edges[k + 1]);
      EXPECT_FLOAT_EQ(v.lookup(tau_mid, static_cast<float>(t.mu[k])),
                      0.5f * (t.P[t.index(i, k)] + t.P[t.index(i + 1, k)]));
      EXPECT_FLOAT_EQ(v.lookup(static_cast<float>(t.tau[i]), mu_mid),
                      0.5f * (t.P[t.index(i, k)] + t.P[t.index(i, k + 1)]));
      EXPECT_FLOAT_EQ(v.lookup(tau_mid, mu_mid),
                      0.25f * (t.P[t.index(i, k)] + t.P[t.index(i + 1, k)] +
                               t.P[t.index(i, k + 1)] + t.P[t.index(i + 1, k + 1)]));
    }
}

TEST(TableLookup, ExactForBilinearFunctions) {
  std::mt19937 rng(12345);
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const ScatteringTable t = make_linear_table(7.3, 101, binning, 72);
    const TableView v = view_of(t);
    const double p_max = kA + kB * 7.3 + kC * 71;
    std::uniform_real_distribution<float> tau_dist(0.0f, 7.3f), mu_dist(-1.0f, 1.0f);
    double worst = 0.0;
    for (int n = 0; n < 20000; ++n) {
      const float tau = tau_dist(rng), mu = mu_dist(rng);
      // The lookup's own bin coordinate, held at the outermost centres.
      const float u = std::clamp(v.bins.position(mu) - 0.5f, 0.0f, 71.0f);
      const double expected = kA + kB * tau + kC * u;
      worst = std::max(worst, std::fabs(v.lookup(tau, mu) - expected));
    }
    EXPECT_LT(worst, 1e-6 * p_max) << to_string(binning);
  }
}

TEST(TableLookup, HoldsEdgeValuesInMuWithoutCountingClamps) {
  const ScatteringTable t = make_test_table(4.0, 5, AngularBinning::UniformTheta, 36);
  const TableView v = view_of(t);
  int clamped = 0;
  for (int i = 0; i < 5; ++i) {
    const float tau = static_cast<float>(t.tau[i]);
    const float first = t.P[t.index(i, 0)], last = t.P[t.index(i, 35)];
    // Between the outermost centre and the domain end the value is held.
    EXPECT_EQ(v.lookup(tau, -1.0f, &clamped), first);
    EXPECT_EQ(v.lookup(tau, static_cast<float>(0.5 * (t.mu_edges[0] + t.mu[0])), &clamped), first);
    EXPECT_EQ(v.lookup(tau, 1.0f, &clamped), last);
    EXPECT_EQ(v.lookup(tau, static_cast<float>(0.5 * (t.mu[35] + 1.0)), &clamped), last);
    // Rounding just past +-1 (a dot product of unit vectors) is no clamp either.
    EXPECT_EQ(v.lookup(tau, 1.0000001f, &clamped), last);
    EXPECT_EQ(v.lookup(tau, -1.5f, &clamped), first);
    EXPECT_EQ(v.lookup(tau, kInf, &clamped), last);
  }
  EXPECT_EQ(clamped, 0);
}

TEST(TableLookup, ClampsTauAndCountsIt) {
  const ScatteringTable t = make_test_table(4.0, 5, AngularBinning::UniformMu, 8);
  const TableView v = view_of(t);
  const float mu = static_cast<float>(t.mu[3]);
  const float at_zero = t.P[t.index(0, 3)], at_max = t.P[t.index(4, 3)];

  int clamped = 0;
  EXPECT_EQ(v.lookup(4.0f, mu, &clamped), at_max);
  EXPECT_EQ(v.lookup(0.0f, mu, &clamped), at_zero);
  EXPECT_EQ(clamped, 0) << "the axis ends are inside the table";

  EXPECT_EQ(v.lookup(4.5f, mu, &clamped), at_max);
  EXPECT_EQ(clamped, 1);
  EXPECT_EQ(v.lookup(kInf, mu, &clamped), at_max);
  EXPECT_EQ(clamped, 2);
  EXPECT_EQ(v.lookup(-0.25f, mu, &clamped), at_zero);
  EXPECT_EQ(clamped, 3);
  EXPECT_EQ(v.lookup(-kInf, mu, &clamped), at_zero);
  EXPECT_EQ(clamped, 4);
  EXPECT_EQ(v.lookup(kNaN, mu, &clamped), at_zero);
  EXPECT_EQ(clamped, 5);
  // A NaN mu is garbage too: counted, and the answer stays finite.
  EXPECT_TRUE(std::isfinite(v.lookup(2.0f, kNaN, &clamped)));
  EXPECT_EQ(clamped, 6);
  // Two bad inputs in one lookup count once.
  EXPECT_TRUE(std::isfinite(v.lookup(kNaN, kNaN, &clamped)));
  EXPECT_EQ(clamped, 7);
  // Counting is optional.
  EXPECT_EQ(v.lookup(9.0f, mu), at_max);
}

// Any input, however wild, gives a value between the table's extremes (and
// would fault under a sanitizer if it read outside P).
TEST(TableLookup, StaysInsideTheTable) {
  const float specials[] = {0.0f, -0.0f, 1e-38f, -1e-38f, 1.0f, -1.0f, 1e30f, -1e30f,
                            std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                            kInf, -kInf, kNaN, 0.999999f, 5.0f, 5.0000005f};
  for (int n_tau : {2, 3, 11})
    for (int n_mu : {1, 2, 36}) {
      const ScatteringTable t = make_test_table(5.0, n_tau, AngularBinning::UniformTheta, n_mu);
      const TableView v = view_of(t);
      const float lo = *std::min_element(t.P.begin(), t.P.end());
      const float hi = *std::max_element(t.P.begin(), t.P.end());
      for (float tau : specials)
        for (float mu : specials) {
          const float p = v.lookup(tau, mu);
          EXPECT_TRUE(p >= lo && p <= hi) << "tau " << tau << " mu " << mu << " gave " << p;
        }
    }
}

TEST(TableLookup, EmptyViewReturnsZero) {
  const TableView empty;
  int clamped = 0;
  EXPECT_EQ(empty.lookup(1.0f, 0.0f, &clamped), 0.0f);
}

}  // namespace
}  // namespace nebula
