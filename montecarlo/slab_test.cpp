#include "montecarlo/slab.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/math.h"
#include "montecarlo/test_stats.h"

namespace nebula {
namespace {

// The exact slab cases (van de Hulst; Chandrasekhar) are in
// validation/montecarlo_validation.cpp and run by validation_tests.
TEST(Slab, AnalogUnscatteredTransmissionFollowsBeerLambertAtOblique) {
  SlabParams p;
  p.albedo = 0.5;
  p.g = 0.3;
  p.tau = 0.7;
  p.incidence_deg = 60;
  p.photons = 400000;
  p.forced_first_scattering = false;
  validate(p);
  const SlabTallies t = simulate_slab_cpu(p, nullptr);
  const double expected = std::exp(-p.tau / 0.5);
  const double got = from_fixed(t.unscattered) / p.photons;
  EXPECT_NEAR(got, expected, 4 * std::sqrt(expected * (1 - expected) / p.photons));
}

TEST(Slab, ForcedAndAnalogAgree) {
  SlabParams p;
  p.albedo = 0.9;
  p.g = 0.75;
  p.tau = 0.3;
  p.incidence_deg = 30;
  p.photons = 400000;
  const SlabResult forced = simulate_slab(p, Backend::Cpu);
  p.forced_first_scattering = false;
  p.seed = 17;
  const SlabResult analog = simulate_slab(p, Backend::Cpu);
  EXPECT_LT(std::fabs(test::z_score(forced.R_diffuse, forced.R_stderr, analog.R_diffuse,
                                    analog.R_stderr)),
            4.0);
  EXPECT_LT(std::fabs(test::z_score(forced.T_total, forced.T_stderr, analog.T_total,
                                    analog.T_stderr)),
            4.0);
  EXPECT_LT(forced.R_stderr, analog.R_stderr);
}

TEST(Slab, RefusesBadInput) {
  SlabParams p;
  p.tau = -1;
  EXPECT_THROW(validate(p), Error);
  p = {};
  p.incidence_deg = 90;
  EXPECT_THROW(validate(p), Error);
  p = {};
  p.photons = 0;
  EXPECT_THROW(validate(p), Error);
}

}  // namespace
}  // namespace nebula
