#include "montecarlo/photon_transport.h"

#include <gtest/gtest.h>

#include "core/math.h"
#include "montecarlo/tabulate.h"

namespace nebula {
namespace {

TEST(SphereGeometry, ExitDistances) {
  const SphereGeometry s{0.62f};
  EXPECT_NEAR(s.exit_distance({0, 0, 0}, normalize({1, 2, 3})), 0.62f, 1e-6f);
  // From the near pole along the axis: the diameter; from the far pole outward: 0.
  EXPECT_NEAR(s.exit_distance({0, 0, -0.62f}, {0, 0, 1}), 1.24f, 1e-6f);
  EXPECT_NEAR(s.exit_distance({0, 0, 0.62f}, {0, 0, 1}), 0.0f, 1e-6f);
  // A chord at impact parameter b has length 2 sqrt(R^2 - b^2).
  const float b = 0.5f, z = -std::sqrt(0.62f * 0.62f - b * b);
  EXPECT_NEAR(s.exit_distance({b, 0, z}, {0, 0, 1}), -2 * z, 2e-6f);
  // Slightly outside through rounding: never negative.
  EXPECT_GE(s.exit_distance({0, 0, 0.6200001f}, {0, 0, 1}), 0.0f);
}

TEST(SlabGeometry, ExitDistances) {
  const SlabGeometry slab{2.0f};
  EXPECT_NEAR(slab.exit_distance({0, 0, 0.5f}, {0, 0, 1}), 1.5f, 1e-6f);
  EXPECT_NEAR(slab.exit_distance({0, 0, 0.5f}, {0, 0, -1}), 0.5f, 1e-6f);
  EXPECT_NEAR(slab.exit_distance({0, 0, 0.5f}, normalize({1, 0, 1})), 1.5f * std::sqrt(2.0f), 1e-5f);
  EXPECT_GT(slab.exit_distance({0, 0, 0.5f}, {1, 0, 0}), 1e30f);
}

// With albedo 1 no light is absorbed: every photon leaves, scattered or not.
TEST(PhotonTransport, ConservesEnergyAtAlbedoOne) {
  for (bool forced : {true, false}) {
    TabulateParams p;
    p.albedo = 1.0;
    p.g = 0.6;
    p.tau_max = 10;
    p.tau_bins = 11;
    p.mu_bins = 24;
    p.photons_per_row = 20000;
    p.forced_first_scattering = forced;
    const Tabulation t = tabulate(p, Backend::Cpu);
    EXPECT_EQ(t.capped_photons, 0u);
    for (int i = 0; i < p.tau_bins; ++i)
      EXPECT_NEAR(t.total[i] + t.unscattered[i], 1.0, 1e-6) << "forced=" << forced << " row " << i;
  }
}

}  // namespace
}  // namespace nebula
