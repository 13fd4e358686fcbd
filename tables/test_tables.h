#pragma once
// Test-only helpers: small, hand-filled tables that pass check_consistency.
#include <cmath>

#include "core/math.h"
#include "tables/scattering_table.h"

namespace nebula::testing {

// Henyey-Greenstein phase function normalised over 4 pi.
inline double henyey_greenstein(double g, double mu) {
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPiD * d * std::sqrt(d));
}

// Recomputes total from P and gives every derived array a plausible value.
inline void finish_table(ScatteringTable& t) {
  for (int i = 0; i < t.n_tau(); ++i) {
    t.total[i] = t.total_from_P(i);
    t.total_stderr[i] = 1e-3 * t.total[i];
    t.unscattered[i] = std::exp(-t.tau[i]);
    for (int k = 0; k < t.n_mu(); ++k) t.P_stderr[t.index(i, k)] = 0.01f * t.P[t.index(i, k)];
  }
}

// P = pi R^2 * 0.6 (1 - e^-tau) p_HG(mu): the shape of a real table (thin
// limit tau p_HG up to the albedo) and total = 0.6 (1 - e^-tau) <= 1. Every
// attribute is set to a distinctive value so round trips are meaningful.
inline ScatteringTable make_test_table(double tau_max = 5.0, int n_tau = 11,
                                       AngularBinning binning = AngularBinning::UniformMu,
                                       int n_mu = 36, double g = 0.6) {
  ScatteringTable t = ScatteringTable::make_axes(tau_max, n_tau, binning, n_mu);
  t.albedo = 0.6;
  t.g = g;
  t.illumination = "parallel";
  t.photons_per_row = 1000003;
  t.thin_boost = 17;
  t.seed = 0xFEDCBA9876543210ull;  // high bit set: uint64 must survive
  t.generator = "nebula-test 0.1.0";
  t.forced_first_scattering = true;
  t.roulette_threshold = 1e-3;
  t.roulette_survival = 0.1;
  t.max_orders = 1000;
  t.capped_photons = 17;
  t.scattering_events = 123456789012ull;
  const double cross_section = kPiD * kVoxelSphereRadius * kVoxelSphereRadius;
  for (int i = 0; i < n_tau; ++i)
    for (int k = 0; k < n_mu; ++k)
      t.P[t.index(i, k)] = static_cast<float>(cross_section * 0.6 * (1.0 - std::exp(-t.tau[i])) *
                                              henyey_greenstein(g, t.mu[k]));
  finish_table(t);
  return t;
}

}  // namespace nebula::testing
