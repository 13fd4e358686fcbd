#include "tables/scattering_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "core/error.h"
#include "core/math.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

using testing::make_test_table;

TEST(ScatteringTable, MakeAxesUniformTauAndBinningEdges) {
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const ScatteringTable t = ScatteringTable::make_axes(3.7, 38, binning, 72);
    ASSERT_EQ(t.n_tau(), 38);
    ASSERT_EQ(t.n_mu(), 72);
    EXPECT_EQ(t.tau.front(), 0.0);
    EXPECT_EQ(t.tau.back(), 3.7);
    EXPECT_EQ(t.tau_max(), 3.7);
    for (int i = 0; i < 38; ++i) EXPECT_NEAR(t.tau[i], 3.7 * i / 37.0, 1e-15);
    const AngularBins bins{binning, 72};
    EXPECT_EQ(t.mu_edges.front(), -1.0);
    EXPECT_EQ(t.mu_edges.back(), 1.0);
    for (int k = 0; k <= 72; ++k) EXPECT_EQ(t.mu_edges[k], bins.edge(k));
    for (int k = 0; k < 72; ++k) {
      EXPECT_EQ(t.mu[k], bins.centre(k));
      EXPECT_LT(t.mu_edges[k], t.mu[k]);
      EXPECT_LT(t.mu[k], t.mu_edges[k + 1]);
    }
    EXPECT_EQ(t.P.size(), 38u * 72u);
    EXPECT_EQ(t.P_stderr.size(), 38u * 72u);
    EXPECT_EQ(t.total.size(), 38u);
    EXPECT_EQ(t.total_stderr.size(), 38u);
    EXPECT_EQ(t.unscattered.size(), 38u);
    EXPECT_EQ(t.bins().kind, binning);
    EXPECT_EQ(t.bins().n, 72);
  }
}

TEST(ScatteringTable, MakeAxesRefusesBadArguments) {
  EXPECT_THROW(ScatteringTable::make_axes(0.0, 10, AngularBinning::UniformMu, 8), Error);
  EXPECT_THROW(ScatteringTable::make_axes(-1.0, 10, AngularBinning::UniformMu, 8), Error);
  EXPECT_THROW(ScatteringTable::make_axes(NAN, 10, AngularBinning::UniformMu, 8), Error);
  EXPECT_THROW(ScatteringTable::make_axes(INFINITY, 10, AngularBinning::UniformMu, 8), Error);
  EXPECT_THROW(ScatteringTable::make_axes(1.0, 1, AngularBinning::UniformMu, 8), Error);
  EXPECT_THROW(ScatteringTable::make_axes(1.0, 10, AngularBinning::UniformMu, 0), Error);
}

// An isotropic F = 1/(4 pi) integrates to 1 over the sphere: checks the
// solid angles and the pi R^2 normalisation of P, for both binnings.
TEST(ScatteringTable, TotalFromIsotropicPIsOne) {
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    ScatteringTable t = ScatteringTable::make_axes(1.0, 2, binning, 90);
    const double cross_section = kPiD * kVoxelSphereRadius * kVoxelSphereRadius;
    for (float& p : t.P) p = static_cast<float>(cross_section / (4.0 * kPiD));
    EXPECT_NEAR(t.total_from_P(0), 1.0, 1e-6);
    EXPECT_NEAR(t.total_from_P(1), 1.0, 1e-6);
  }
}

// The median relative standard error of the entries: make_test_table gives
// every entry 1%; a table without scattered light has none to state.
TEST(ScatteringTable, MedianRelativeErrorOfTheEntries) {
  ScatteringTable t = make_test_table();
  EXPECT_NEAR(t.median_relative_error(), 0.01, 1e-6);
  for (size_t i = 0; i < t.P.size(); ++i)
    if (i % 4 != 0) t.P_stderr[i] = 0.5f * t.P[i];  // three entries in four at 50%
  EXPECT_NEAR(t.median_relative_error(), 0.5, 1e-6);
  ScatteringTable empty = ScatteringTable::make_axes(1.0, 2, AngularBinning::UniformMu, 4);
  EXPECT_EQ(empty.median_relative_error(), 0.0);
}

TEST(ScatteringTable, TestTableIsConsistent) {
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const ScatteringTable t = make_test_table(5.0, 11, binning, 72);
    EXPECT_NO_THROW(t.check_consistency("test"));
    EXPECT_NEAR(t.total.back(), 0.6 * (1.0 - std::exp(-5.0)), 0.01);  // HG sampled at centres
  }
}

// Each mutation must be refused, naming the source and the field in one line.
struct Mutation {
  const char* name;
  const char* field;
  std::function<void(ScatteringTable&)> apply;
};

class Refused : public ::testing::TestWithParam<Mutation> {};

TEST_P(Refused, NamesSourceAndField) {
  ScatteringTable t = make_test_table();
  GetParam().apply(t);
  try {
    t.check_consistency("cloud.h5");
    FAIL() << "accepted a table with " << GetParam().name;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("cloud.h5: ", 0), 0u) << message;
    EXPECT_NE(message.find(std::string(": ") + GetParam().field + ": expected"), std::string::npos)
        << message;
    EXPECT_NE(message.find("found"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();

INSTANTIATE_TEST_SUITE_P(
    ScatteringTable, Refused,
    ::testing::Values(
        Mutation{"albedo_above_one", "albedo", [](ScatteringTable& t) { t.albedo = 1.5; }},
        Mutation{"albedo_negative", "albedo", [](ScatteringTable& t) { t.albedo = -0.1; }},
        Mutation{"albedo_nan", "albedo", [](ScatteringTable& t) { t.albedo = kNaN; }},
        Mutation{"g_one", "g", [](ScatteringTable& t) { t.g = 1.0; }},
        Mutation{"g_nan", "g", [](ScatteringTable& t) { t.g = kNaN; }},
        Mutation{"phase", "phase", [](ScatteringTable& t) { t.phase = "rayleigh"; }},
        Mutation{"geometry", "geometry", [](ScatteringTable& t) { t.geometry = "cube"; }},
        Mutation{"illumination", "illumination",
                 [](ScatteringTable& t) { t.illumination = "diffuse"; }},
        Mutation{"rng", "rng", [](ScatteringTable& t) { t.rng = "mt19937"; }},
        Mutation{"schema", "schema_version", [](ScatteringTable& t) { t.schema_version = 2; }},
        Mutation{"no_photons", "photons_per_row", [](ScatteringTable& t) { t.photons_per_row = 0; }},
        Mutation{"no_generator", "generator", [](ScatteringTable& t) { t.generator.clear(); }},
        Mutation{"roulette_nan", "roulette_survival",
                 [](ScatteringTable& t) { t.roulette_survival = kNaN; }},
        Mutation{"binning_enum", "mu_binning",
                 [](ScatteringTable& t) { t.mu_binning = static_cast<AngularBinning>(7); }},
        Mutation{"one_row", "/tau",
                 [](ScatteringTable& t) {
                   t.tau.resize(1);
                   t.P.resize(t.n_mu());
                 }},
        Mutation{"tau_not_from_zero", "/tau",
                 [](ScatteringTable& t) {
                   for (double& x : t.tau) x += 0.1;
                 }},
        Mutation{"tau_not_uniform", "/tau", [](ScatteringTable& t) { t.tau[3] *= 1.001; }},
        Mutation{"tau_max_zero", "/tau",
                 [](ScatteringTable& t) {
                   for (double& x : t.tau) x = 0.0;
                 }},
        Mutation{"edges_off", "/mu_edges", [](ScatteringTable& t) { t.mu_edges[5] += 1e-6; }},
        Mutation{"edges_short", "/mu_edges", [](ScatteringTable& t) { t.mu_edges.pop_back(); }},
        Mutation{"centres_off", "/mu", [](ScatteringTable& t) { t.mu[7] = t.mu_edges[7]; }},
        Mutation{"other_binning", "/mu_edges",
                 [](ScatteringTable& t) { t.mu_binning = AngularBinning::UniformTheta; }},
        Mutation{"P_short", "/P", [](ScatteringTable& t) { t.P.pop_back(); }},
        Mutation{"P_negative", "/P", [](ScatteringTable& t) { t.P[40] = -1e-3f; }},
        Mutation{"P_nan", "/P", [](ScatteringTable& t) { t.P[40] = NAN; }},
        Mutation{"P_stderr_inf", "/P_stderr", [](ScatteringTable& t) { t.P_stderr[2] = INFINITY; }},
        Mutation{"P_stderr_short", "/P_stderr", [](ScatteringTable& t) { t.P_stderr.clear(); }},
        Mutation{"total_above_one", "/total", [](ScatteringTable& t) { t.total[4] = 1.5; }},
        Mutation{"total_not_from_P", "/total", [](ScatteringTable& t) { t.total[4] *= 1.001; }},
        Mutation{"P_not_total", "/total", [](ScatteringTable& t) { t.P[t.index(6, 3)] *= 1.5f; }},
        Mutation{"total_stderr_nan", "/total_stderr",
                 [](ScatteringTable& t) { t.total_stderr[0] = kNaN; }},
        Mutation{"unscattered_negative", "/unscattered",
                 [](ScatteringTable& t) { t.unscattered[1] = -0.01; }},
        Mutation{"unscattered_short", "/unscattered",
                 [](ScatteringTable& t) { t.unscattered.pop_back(); }}),
    [](const ::testing::TestParamInfo<Mutation>& info) { return std::string(info.param.name); });

// float32 rounding of P must not trip the total check, and a total within
// the stated tolerance (1e-4 relative) is accepted.
TEST(ScatteringTable, TotalToleranceAcceptsFloatRounding) {
  ScatteringTable t = make_test_table(20.0, 41, AngularBinning::UniformTheta, 180);
  for (double& total : t.total) total *= 1.0 + 5e-5;
  EXPECT_NO_THROW(t.check_consistency("test"));
  t.total[40] *= 1.0 + 2e-4;
  EXPECT_THROW(t.check_consistency("test"), Error);
}

TEST(ScatteringTable, PencilIlluminationAccepted) {
  ScatteringTable t = make_test_table();
  t.illumination = "pencil";
  EXPECT_NO_THROW(t.check_consistency("test"));
}

}  // namespace
}  // namespace nebula
