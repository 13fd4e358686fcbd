#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/gpu.h"
#include "core/test_support.h"
#include "tables/table_lookup_gpu.h"
#include "tables/table_lookup.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

using testing::make_test_table;

// Random points over and beyond the table, plus every special value.
void make_points(float tau_max, std::vector<float>& tau, std::vector<float>& mu) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> tau_dist(-0.25f * tau_max, 1.25f * tau_max);
  std::uniform_real_distribution<float> mu_dist(-1.1f, 1.1f);
  for (int n = 0; n < 50000; ++n) {
    tau.push_back(tau_dist(rng));
    mu.push_back(mu_dist(rng));
  }
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float specials[] = {0.0f, -0.0f, tau_max, -1.0f, 1.0f, inf, -inf, nan, 1e-30f, 1e30f};
  for (float a : specials)
    for (float b : specials) {
      tau.push_back(a);
      mu.push_back(b);
    }
}

TEST(TableLookupGpu, AgreesWithTheHost) {
  NEBULA_SKIP_WITHOUT_GPU();
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const ScatteringTable t = make_test_table(20.0, 201, binning, 72, 0.8);
    const TableView host = view_of(t);
    std::vector<float> tau, mu;
    make_points(host.tau_max, tau, mu);

    int host_clamped = 0;
    std::vector<float> expected(tau.size());
    for (size_t j = 0; j < tau.size(); ++j) expected[j] = host.lookup(tau[j], mu[j], &host_clamped);

    uint64_t gpu_clamped = 0;
    const std::vector<float> got = lookup_batch_gpu(t, tau, mu, &gpu_clamped);
    ASSERT_EQ(got.size(), tau.size());
    EXPECT_EQ(gpu_clamped, static_cast<uint64_t>(host_clamped)) << to_string(binning);
    EXPECT_GT(host_clamped, 10000) << "the points should leave the table often";

    // The bound is 1e-6 relative plus, for uniform-theta, the change of the
    // value under 2 ulp of the float bin coordinate u ~ n (1 - theta / pi):
    // CUDA's acosf (within 2 ulp, glibc's within 1) and FMA contraction can
    // round u to a neighbouring float, which moves P by ulp(u) |dP/du|
    // (about 2e-6 relative near the forward peak). uniform-mu computes u
    // with the same operations on both sides, so it gets no such allowance.
    double worst = 0.0;  // |GPU - host| / bound
    size_t worst_at = 0;
    for (size_t j = 0; j < tau.size(); ++j) {
      double bound = 1e-6 * std::max(std::fabs(expected[j]), 1e-30f);
      if (binning == AngularBinning::UniformTheta && !std::isnan(mu[j])) {
        const float position = host.bins.position(mu[j]);
        const double ulp_u = std::nextafter(position, INFINITY) - position;
        const int k = std::clamp(static_cast<int>(position - 0.5f), 0, host.n_mu - 2);
        const float tau_c = std::isnan(tau[j]) ? 0.0f : std::clamp(tau[j], 0.0f, host.tau_max);
        const int i = std::min(static_cast<int>(tau_c / host.tau_max * (host.n_tau - 1)), host.n_tau - 2);
        double slope = 0.0;  // |dP/du| over the cell, its neighbours and both rows
        for (int row : {i, i + 1})
          for (int c = std::max(k - 1, 0); c <= std::min(k + 1, host.n_mu - 2); ++c)
            slope = std::max(slope, double(std::fabs(host.at(row, c + 1) - host.at(row, c))));
        bound += 2.0 * ulp_u * slope;
      }
      const double ratio = got[j] == expected[j] ? 0.0 : std::fabs(got[j] - expected[j]) / bound;
      if (ratio > worst) {
        worst = ratio;
        worst_at = j;
      }
    }
    std::printf("%s: worst GPU-host difference is %.3g of its bound (tau %g, mu %g)\n",
                to_string(binning), worst, tau[worst_at], mu[worst_at]);
    EXPECT_LE(worst, 1.0) << to_string(binning) << " at tau " << tau[worst_at] << " mu "
                          << mu[worst_at] << ": host " << expected[worst_at] << " GPU "
                          << got[worst_at];
  }
}

TEST(TableLookupGpu, MismatchedInputsAreRefused) {
  NEBULA_SKIP_WITHOUT_GPU();
  const ScatteringTable t = make_test_table();
  EXPECT_THROW(lookup_batch_gpu(t, {1.0f, 2.0f}, {0.5f}, nullptr), Error);
  EXPECT_TRUE(lookup_batch_gpu(t, {}, {}, nullptr).empty());
}

// Without a usable GPU the entry points fail with an Error, never a crash.
TEST(TableLookupGpu, WithoutAGpuTheBatchFailsCleanly) {
  std::string reason;
  if (gpu_available(&reason)) GTEST_SKIP() << "a GPU is present";
  const ScatteringTable t = make_test_table();
  EXPECT_THROW(lookup_batch_gpu(t, {1.0f}, {0.5f}, nullptr), Error);
}

}  // namespace
}  // namespace nebula
