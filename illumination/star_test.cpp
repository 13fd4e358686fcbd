#include "illumination/star.h"
#include "illumination/filters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"
#include "core/math.h"

namespace nebula {
namespace {

double passband_width_nm(const Passband& p) {
  return passband_integral(p, [](double) { return 1.0; }, 1);
}

TEST(Star, EffectiveTemperaturesOfTheSixClasses) {
  EXPECT_EQ(effective_temperature_K("O5V"), 41400.0);
  EXPECT_EQ(effective_temperature_K("B0V"), 31400.0);
  EXPECT_EQ(effective_temperature_K("B5V"), 15700.0);
  EXPECT_EQ(effective_temperature_K("A0V"), 9700.0);
  EXPECT_EQ(effective_temperature_K("G2V"), 5770.0);
  EXPECT_EQ(effective_temperature_K("M0V"), 3850.0);
  EXPECT_EQ(effective_temperature_K("g2v"), 5770.0);  // case-insensitive
  EXPECT_EQ(effective_temperature_K("m0V"), 3850.0);
  EXPECT_EQ(known_spectral_classes().size(), 6u);
}

TEST(Star, RefusesUnknownClasses) {
  for (const char* name : {"G2", "K0V", "G2III", " G2V", "", "G2V "}) {
    try {
      effective_temperature_K(name);
      ADD_FAILURE() << "'" << name << "' was accepted";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("'") + name + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("O5V, B0V, B5V, A0V, G2V, M0V"), std::string::npos) << message;
    }
  }
}

// The three Johnson bands of band_fractions, by name.
struct BandFluxes {
  double B, V, R;
};
BandFluxes star_band_fractions(double T, const Passband& B, const Passband& V, const Passband& R) {
  const std::vector<double> f = band_fractions(T, {B, V, R});
  return {f[0], f[1], f[2]};
}

TEST(Star, RefusesNonPositiveTemperature) {
  const Passband V = load_filter("V");
  for (double T : {0.0, -5770.0, double(NAN), double(INFINITY)}) {
    EXPECT_THROW(planck_radiance(550e-9, T), Error) << T;
    EXPECT_THROW(planck_total_radiance(T), Error) << T;
    EXPECT_THROW(band_fraction(T, V), Error) << T;
    EXPECT_THROW(star_band_fractions(T, V, V, V), Error) << T;
  }
  try {
    band_fraction(0.0, V);
    ADD_FAILURE() << "T = 0 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("temperature T = 0 K"), std::string::npos) << e.what();
  }
  EXPECT_THROW(planck_radiance(0.0, 5770.0), Error);
}

// sigma computed from the exact constants equals CODATA 2018's
// 5.670374419e-8 W m^-2 K^-4 (itself rounded to 10 digits).
TEST(Star, StefanBoltzmannConstant) {
  EXPECT_NEAR(stefan_boltzmann_constant(), 5.670374419e-8, 1e-9 * 5.670374419e-8);
}

// The maximum of B_lambda lies at b / T, b = 2.897771955e-3 m K (CODATA
// 2018, Wien's displacement constant). A golden-section search locates it
// to 1e-9 relative; the bound 1e-4 is the brief's.
TEST(Star, WienDisplacement) {
  constexpr double kWien = 2.897771955e-3;
  for (double T : {3850.0, 5770.0, 9700.0, 41400.0}) {
    double lo = 0.3 * kWien / T, hi = 3.0 * kWien / T;
    const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
    while (hi - lo > 1e-9 * lo) {
      const double left = hi - golden * (hi - lo), right = lo + golden * (hi - lo);
      if (planck_radiance(left, T) < planck_radiance(right, T)) {
        lo = left;
      } else {
        hi = right;
      }
    }
    const double peak = 0.5 * (lo + hi);
    EXPECT_NEAR(peak * T / kWien, 1.0, 1e-4) << T;
  }
}

// integral B_lambda d lambda = sigma T^4 / pi. Simpson's rule in ln lambda
// (integrand lambda B_lambda, smooth and bell-shaped) over 1e-2 to 1e4 times
// the peak wavelength: the tails beyond are below 1e-10 of the total.
TEST(Star, PlanckIntegratesToStefanBoltzmann) {
  for (double T : {3850.0, 5770.0, 41400.0}) {
    const double peak = 2.897771955e-3 / T;
    const double a = std::log(1e-2 * peak), b = std::log(1e4 * peak);
    const int n = 20000;  // even
    const double h = (b - a) / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double lambda = std::exp(a + i * h);
      const double weight = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      sum += weight * lambda * planck_radiance(lambda, T);
    }
    const double numeric = sum * h / 3.0;
    EXPECT_NEAR(numeric / planck_total_radiance(T), 1.0, 1e-6) << T;
    EXPECT_NEAR(planck_total_radiance(T), 5.670374419e-8 * std::pow(T, 4) / kPiD,
                1e-9 * planck_total_radiance(T));
  }
}

class BandFractionsTest : public ::testing::Test {
 protected:
  Passband B = load_filter("B"), V = load_filter("V"), R = load_filter("R");
};

TEST_F(BandFractionsTest, ArePartsOfTheWhole) {
  for (const std::string& name : known_spectral_classes()) {
    const BandFluxes f = star_band_fractions(effective_temperature_K(name), B, V, R);
    std::printf("  %s (%5.0f K): B %.5f V %.5f R %.5f   B/R %.4f\n", name.c_str(),
                effective_temperature_K(name), f.B, f.V, f.R, f.B / f.R);
    for (double fraction : {f.B, f.V, f.R}) {
      EXPECT_GT(fraction, 0.0) << name;
      EXPECT_LT(fraction, 1.0) << name;
    }
    // The B and R passbands barely overlap V's, and each response is <= 1,
    // so the three cannot pass more than the whole spectrum.
    EXPECT_LT(f.B + f.V + f.R, 1.0) << name;
  }
}

// Hotter stars are bluer: with the classes listed hottest first, the ratio
// of B to R fractions falls strictly from O5V to M0V (and B/V, V/R too).
TEST_F(BandFractionsTest, HotterStarsAreBluer) {
  double previous_B_over_R = INFINITY, previous_B_over_V = INFINITY, previous_V_over_R = INFINITY;
  for (const std::string& name : known_spectral_classes()) {
    const BandFluxes f = star_band_fractions(effective_temperature_K(name), B, V, R);
    EXPECT_LT(f.B / f.R, previous_B_over_R) << name;
    EXPECT_LT(f.B / f.V, previous_B_over_V) << name;
    EXPECT_LT(f.V / f.R, previous_V_over_R) << name;
    previous_B_over_R = f.B / f.R;
    previous_B_over_V = f.B / f.V;
    previous_V_over_R = f.V / f.R;
  }
}

// A Sun-like G2V black body (5770 K) peaks at b/T = 502 nm, between the B
// (441 nm) and V (551 nm) means. Per nm of passband (fraction divided by the
// passband's width, integral T d lambda), the bands therefore rank by how
// far their means lie from the peak: V (49 nm away) > B (61 nm, and the
// Planck curve falls faster on the blue side) > R (157 nm). And against the
// A0V star, the zero point of Vega magnitudes, the Sun is redder: its
// synthetic B-V and V-R colours are positive.
TEST_F(BandFractionsTest, SunLikeStarPeaksNearV) {
  const double T = effective_temperature_K("G2V");
  const BandFluxes sun = star_band_fractions(T, B, V, R);
  const double per_nm_B = sun.B / passband_width_nm(B);
  const double per_nm_V = sun.V / passband_width_nm(V);
  const double per_nm_R = sun.R / passband_width_nm(R);
  std::printf("  G2V per nm of passband: B %.4e V %.4e R %.4e\n", per_nm_B, per_nm_V, per_nm_R);
  EXPECT_GT(per_nm_V, per_nm_B);
  EXPECT_GT(per_nm_B, per_nm_R);
  EXPECT_GT(2.897771955e-3 / T * 1e9, mean_wavelength_nm(B));
  EXPECT_LT(2.897771955e-3 / T * 1e9, mean_wavelength_nm(V));

  const BandFluxes vega_like = star_band_fractions(effective_temperature_K("A0V"), B, V, R);
  const double B_minus_V = -2.5 * std::log10((sun.B / sun.V) / (vega_like.B / vega_like.V));
  const double V_minus_R = -2.5 * std::log10((sun.V / sun.R) / (vega_like.V / vega_like.R));
  std::printf("  G2V black body relative to A0V: B-V %.3f, V-R %.3f mag\n", B_minus_V, V_minus_R);
  EXPECT_GT(B_minus_V, 0.0);
  EXPECT_GT(V_minus_R, 0.0);
}

// kPassbandSubdivisions (128) against 1024 steps per interval: converged to
// 1e-6 relative, far below what a per-band luminosity needs.
TEST_F(BandFractionsTest, IsConverged) {
  for (double T : {3850.0, 41400.0}) {
    for (const Passband* p : {&B, &V, &R}) {
      const double fine =
          passband_integral(*p, [&](double nm) { return planck_radiance(nm * 1e-9, T); }, 1024) *
          1e-9 / planck_total_radiance(T);
      EXPECT_NEAR(band_fraction(T, *p) / fine, 1.0, 1e-6) << p->name << " " << T;
    }
  }
}

}  // namespace
}  // namespace nebula
