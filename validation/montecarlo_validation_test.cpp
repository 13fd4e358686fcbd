#include "validation/montecarlo_validation.h"

#include <gtest/gtest.h>

namespace nebula {
namespace {

// The documented validation set (what `nebula validate montecarlo` prints)
// passes on the CPU at a quarter of its photons (tolerances scale with the
// standard errors, so a smaller run is as strict in sigma).
TEST(MonteCarloValidation, EveryCasePasses) {
  const std::vector<ValidationRow> rows = validate_montecarlo(Backend::Cpu, 1.0);
  EXPECT_GE(rows.size(), 15u);
  for (const ValidationRow& r : rows)
    EXPECT_TRUE(r.pass) << r.check << ": expected " << r.expected << ", measured " << r.measured
                        << ", tolerance " << r.tolerance << " (" << r.basis << ")";
}

// Uniform-theta bins follow a forward-peaked phase function better than
// uniform-mu bins; both are exact for isotropic scattering.
TEST(BinningComparison, UniformThetaResolvesForwardPeaks) {
  const std::vector<BinningRow> rows = compare_binnings({0.0, 0.9}, 72, 1e6);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_LT(rows[0].interp_rms, 1e-6);  // g = 0: constant phase function
  EXPECT_LT(rows[1].interp_rms, 1e-6);
  EXPECT_GT(rows[2].interp_rms, 2 * rows[3].interp_rms);  // g = 0.9
  EXPECT_GT(std::fabs(rows[2].forward_error), std::fabs(rows[3].forward_error));
}

}  // namespace
}  // namespace nebula
