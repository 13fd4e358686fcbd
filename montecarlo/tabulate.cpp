#include "montecarlo/tabulate.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/gpu.h"
#include "core/memory.h"
#include "core/math.h"

namespace nebula {

void validate(const TabulateParams& p) {
  if (!(p.albedo >= 0.0 && p.albedo <= 1.0))
    throw ParameterError("albedo", "must be in [0, 1], got " + to_text(p.albedo));
  if (!(std::fabs(p.g) < 1.0))
    throw ParameterError("g", "|g| must be below 1 (g = +-1 is a delta function), got " + to_text(p.g));
  if (!(p.tau_max > 0.0) || !std::isfinite(p.tau_max))
    throw ParameterError("tau_max", "must be a positive finite optical depth, got " + to_text(p.tau_max));
  if (p.tau_bins < 2) throw ParameterError("tau_bins", "need at least 2 rows, got " + to_text(p.tau_bins));
  if (p.mu_bins < 2 || p.mu_bins > kMaxMuBins)
    throw ParameterError("mu_bins", "need 2 to " + to_text(kMaxMuBins) + " bins, got " + to_text(p.mu_bins));
  // Per bin: the tallies (two 64-bit sums), P and its error in double, the
  // table's float copies; per row a few doubles. Refused before allocating.
  const double bytes = double(p.tau_bins) * (double(p.mu_bins) * (2 * 8 + 2 * 8 + 2 * 4) + 8 * 8);
  if (const std::string over = over_memory_limit(bytes); !over.empty())
    throw ParameterError("tau_bins", to_text(p.tau_bins) + " rows of " + to_text(p.mu_bins) + " bins " + over);
  if (p.photons_per_row < 2 || p.photons_per_row > kMaxPhotonsPerRow)
    throw ParameterError("photons_per_row", "need 2 to 2^30 photons per row, got " + to_text(double(p.photons_per_row)));
  if (p.thin_boost < 1 || p.thin_boost > kMaxThinBoost)
    throw ParameterError("thin_boost", "must be 1 to " + to_text(kMaxThinBoost) + ", got " + to_text(p.thin_boost));
  if (double(p.photons_per_row) * p.thin_boost > double(kMaxPhotonsPerRow))
    throw ParameterError("photons_per_row", to_text(double(p.photons_per_row)) + " photons per row x thin_boost " +
                                                to_text(p.thin_boost) + " is more than 2^30 in a thin row");
  if (!(p.roulette.threshold > 0 && p.roulette.threshold < 1) ||
      !(p.roulette.survival > 0 && p.roulette.survival <= 1) || p.roulette.max_orders < 1)
    throw ParameterError("roulette", "threshold in (0, 1), survival in (0, 1] and max orders >= 1 required");
  // Survivors' weight threshold / survival must stay below 1 for the fixed-point tallies.
  if (p.roulette.threshold / p.roulette.survival > 1.0f)
    throw ParameterError("roulette", "threshold / survival must not exceed 1");
}

double tau_of_row(const TabulateParams& p, int row) {
  return p.tau_max * row / (p.tau_bins - 1);
}

uint64_t photons_of_row(const TabulateParams& p, int row) {
  const double tau = tau_of_row(p, row);
  // floor(1 / tau) without the division's overflow at tau = 0; the 1e-9 keeps
  // rows like 0.05, whose double is a hair above 1/20, at 20.
  const double boost = tau * p.thin_boost >= 1.0 ? std::floor(1.0 / tau + 1e-9) : double(p.thin_boost);
  return p.photons_per_row * static_cast<uint64_t>(std::fmax(1.0, boost));
}

uint64_t photons_of_table(const TabulateParams& p) {
  uint64_t n = 0;
  for (int i = 0; i < p.tau_bins; ++i) n += photons_of_row(p, i);
  return n;
}

double weight_scale(const TabulateParams& p, int row) {
  if (!p.forced_first_scattering) return 1.0;
  if (p.albedo == 0.0) return 0.0;
  const double sigma_ext = tau_of_row(p, row) / p.albedo;
  // The longest chord is the diameter, for either beam.
  return -std::expm1(-sigma_ext * 2.0 * kVoxelSphereRadius);
}

SphereRow make_sphere_row(const TabulateParams& p, int row) {
  SphereRow r{};
  r.geometry.radius = static_cast<float>(kVoxelSphereRadius);
  r.source = {p.beam, r.geometry.radius};
  const double sigma_ext = p.albedo > 0 ? tau_of_row(p, row) / p.albedo : 0.0;
  r.medium = {static_cast<float>(sigma_ext), static_cast<float>(p.albedo), static_cast<float>(p.g)};
  r.roulette = p.roulette;
  r.stream = {p.seed, static_cast<uint32_t>(row), kPurposeSphere};
  r.bins = {p.binning, p.mu_bins};
  r.forced_first = p.forced_first_scattering;
  r.photons = static_cast<uint32_t>(photons_of_row(p, row));
  const double scale = weight_scale(p, row);
  r.inv_weight_scale = scale > 0 ? static_cast<float>(1.0 / scale) : 0.0f;
  return r;
}

void SphereTallies::resize(int tau, int mu) {
  n_tau = tau;
  n_mu = mu;
  sum_w.assign(size_t(tau) * mu, 0);
  sum_w2.assign(size_t(tau) * mu, 0);
  unscattered.assign(tau, 0);
  events.assign(tau, 0);
  capped.assign(tau, 0);
  capped_weight.assign(tau, 0);
}

Tabulation finish_tabulation(const TabulateParams& p, const SphereTallies& t) {
  Tabulation out;
  out.params = p;
  const int n_tau = p.tau_bins, n_mu = p.mu_bins;
  const AngularBins bins{p.binning, n_mu};
  // P = (pi R^2 / l^2) F: light per steradian per unit face area (DESIGN.md).
  const double cross_section = kPiD * kVoxelSphereRadius * kVoxelSphereRadius;
  out.tau.resize(n_tau);
  out.P.assign(size_t(n_tau) * n_mu, 0.0);
  out.P_stderr.assign(size_t(n_tau) * n_mu, 0.0);
  out.total.assign(n_tau, 0.0);
  out.total_stderr.assign(n_tau, 0.0);
  out.unscattered.assign(n_tau, 0.0);
  for (int i = 0; i < n_tau; ++i) {
    out.tau[i] = tau_of_row(p, i);
    const double n = static_cast<double>(photons_of_row(p, i));
    const double scale = weight_scale(p, i);
    double s1_row = 0, s2_row = 0;
    for (int k = 0; k < n_mu; ++k) {
      const double s1 = from_fixed(t.sum_w[size_t(i) * n_mu + k]);
      const double s2 = from_fixed(t.sum_w2[size_t(i) * n_mu + k]);
      s1_row += s1;
      s2_row += s2;
      const double mean = s1 / n;
      const double var = std::fmax(s2 / n - mean * mean, 0.0);
      const double per_sr = cross_section * scale / bins.solid_angle(k);
      out.P[size_t(i) * n_mu + k] = per_sr * mean;
      out.P_stderr[size_t(i) * n_mu + k] = per_sr * std::sqrt(var / (n - 1));
    }
    const double mean = s1_row / n;
    out.total[i] = scale * mean;
    out.total_stderr[i] = scale * std::sqrt(std::fmax(s2_row / n - mean * mean, 0.0) / (n - 1));
    out.unscattered[i] = from_fixed(t.unscattered[i]) / n;
    out.scattering_events += t.events[i];
    out.capped_photons += t.capped[i];
    out.capped_weight = std::fmax(out.capped_weight, scale * from_fixed(t.capped_weight[i]) / n);
  }
  if (p.albedo == 0.0) {
    // No light scatters; the limit a -> 0 at fixed tau_sct is an opaque sphere.
    for (int i = 1; i < n_tau; ++i) out.unscattered[i] = 0.0;
  }
  return out;
}

Tabulation tabulate(const TabulateParams& p, Backend backend, Progress* progress) {
  validate(p);
  const auto start = std::chrono::steady_clock::now();
  SphereTallies tallies;
  if (p.albedo == 0.0) {
    tallies.resize(p.tau_bins, p.mu_bins);
    for (int i = 0; i < p.tau_bins; ++i)
      tallies.unscattered[i] = to_fixed(1.0f) * photons_of_row(p, i);
  } else if (backend == Backend::Cuda) {
    tallies = tabulate_sphere_cuda(p, progress);
  } else {
    tallies = tabulate_sphere_cpu(p, progress);
  }
  Tabulation out = finish_tabulation(p, tallies);
  out.compute_seconds = tallies.compute_seconds;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.device = backend == Backend::Cuda ? gpu_description() : "cpu (TBB)";
  return out;
}

}  // namespace nebula
