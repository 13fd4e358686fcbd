#include "validation/montecarlo_validation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/math.h"
#include "core/philox.h"
#include "montecarlo/henyey_greenstein.h"
#include "montecarlo/slab.h"
#include "montecarlo/tabulate.h"
#include "tables/scattering_table.h"
#include "tables/table_lookup.h"

namespace nebula {
namespace {

std::string fmt(const char* format, double v) {
  char buf[160];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

ValidationRow within(std::string check, double expected, double measured, double tolerance,
                     std::string basis) {
  return {std::move(check), expected, measured, tolerance, std::move(basis),
          std::fabs(measured - expected) <= tolerance};
}

uint64_t photons(double base, double effort) {
  return static_cast<uint64_t>(std::max(1000.0, base * effort));
}

void slab_cases(Backend b, double effort, std::vector<ValidationRow>& rows) {
  // van de Hulst (1980); the MCML reference case (Wang, Jacques & Zheng 1995).
  SlabParams vdh;
  vdh.albedo = 0.9;
  vdh.g = 0.75;
  vdh.tau = 2.0;
  vdh.photons = photons(4e6, effort);
  const SlabResult r = simulate_slab(vdh, b);
  rows.push_back(within("slab a=0.9 g=0.75 tau=2: diffuse reflectance", 0.09739, r.R_diffuse,
                        4 * r.R_stderr, "4 standard errors"));
  rows.push_back(within("slab a=0.9 g=0.75 tau=2: total transmittance", 0.66096, r.T_total,
                        4 * r.T_stderr, "4 standard errors"));
  // Chandrasekhar: R = 1 - H(1) sqrt(1 - a), H(1) = 1.59822 for a = 0.8.
  SlabParams semi;
  semi.albedo = 0.8;
  semi.g = 0.0;
  semi.tau = 1e6;
  semi.photons = photons(1e6, effort);
  const SlabResult s = simulate_slab(semi, b);
  rows.push_back(within("semi-infinite isotropic a=0.8: reflectance", 0.28525, s.R_diffuse,
                        4 * s.R_stderr, "4 standard errors"));
}

void thin_limit_cases(Backend b, double effort, std::vector<ValidationRow>& rows) {
  for (double g : {-0.5, 0.0, 0.6, 0.9}) {
    TabulateParams p;
    p.g = g;
    p.tau_max = 1e-4;
    p.tau_bins = 2;
    p.photons_per_row = photons(1e6, effort);
    const Tabulation t = tabulate(p, b);
    const AngularBins bins = t.bins();
    const double tau = t.tau[1];
    const double bias = 2 * (2 * kVoxelSphereRadius * tau / p.albedo);  // first-order attenuation
    double worst = 0;  // largest |error| / allowed over the bins
    for (int k = 0; k < p.mu_bins; ++k) {
      const double expected = hg_bin_mean(g, bins.edge(k), bins.edge(k + 1));
      const double got = t.P[p.mu_bins + k] / tau, se = t.P_stderr[p.mu_bins + k] / tau;
      worst = std::max(worst, std::fabs(got - expected) / (4 * se + bias * expected));
    }
    rows.push_back(within(fmt("thin limit P/tau = p_HG, g=%+.1f: worst bin error / bound", g), 0.0,
                          worst, 1.0, "bound = 4 std. errors + first-order attenuation"));
  }
}

void conservation_case(Backend b, double effort, std::vector<ValidationRow>& rows) {
  TabulateParams p;
  p.albedo = 1.0;
  p.tau_bins = 11;
  p.photons_per_row = photons(2e4, effort);
  const Tabulation t = tabulate(p, b);
  double worst = 0;
  for (int i = 0; i < p.tau_bins; ++i) worst = std::max(worst, std::fabs(t.total[i] + t.unscattered[i] - 1));
  rows.push_back(within("a=1: scattered + unscattered - 1, worst row", 0.0, worst, 1e-6,
                        "float rounding"));
}

// Equal-probability bins by bisection on the exact CDF, chi-square at p = 1e-4.
void chi_square_cases(double effort, std::vector<ValidationRow>& rows) {
  const int bins = 50;
  const auto n = static_cast<uint32_t>(photons(1e6, effort));
  const double a = 2.0 / (9.0 * (bins - 1)), c = 1 - a + 3.719 * std::sqrt(a);
  const double critical = (bins - 1) * c * c * c;  // Wilson-Hilferty
  for (double g : {-0.9, -0.3, 0.0, 1e-4, 0.6, 0.95, 0.99}) {
    std::vector<double> edges(bins + 1, -1.0);
    edges[bins] = 1.0;
    for (int k = 1; k < bins; ++k) {
      double lo = -1, hi = 1;
      for (int it = 0; it < 80; ++it) {
        const double mid = 0.5 * (lo + hi);
        (hg_cdf(g, mid) < double(k) / bins ? lo : hi) = mid;
      }
      edges[k] = 0.5 * (lo + hi);
    }
    std::vector<double> count(bins, 0);
    for (uint32_t i = 0; i < n; ++i) {
      const HgSample s = hg_sample(float(g), philox_uniform4(2024, 0, i, 1, 0).u0);
      const double cs = s.cos_theta, s2 = double(s.sin_theta) * s.sin_theta;
      const double mu = cs >= 0 ? 1 - s2 / (1 + cs) : -1 + s2 / (1 - cs);
      const int k = int(std::upper_bound(edges.begin(), edges.end(), mu) - edges.begin()) - 1;
      count[std::clamp(k, 0, bins - 1)] += 1;
    }
    double chi2 = 0;
    for (double v : count) chi2 += (v - double(n) / bins) * (v - double(n) / bins) / (double(n) / bins);
    rows.push_back({fmt("HG sampling chi-square (49 dof), g=%+.4g", g), 49.0, chi2, critical - 49.0,
                    "chi-square at p = 1e-4", chi2 < critical});
  }
}

void figure4_cases(Backend b, double effort, std::vector<ValidationRow>& rows) {
  TabulateParams p;
  p.beam = Beam::Pencil;  // the paper's configuration
  p.tau_bins = 21;
  p.photons_per_row = photons(2e4, effort);
  const Tabulation t = tabulate(p, b);
  const int n = p.tau_bins;
  const int peak = int(std::max_element(t.total.begin(), t.total.end()) - t.total.begin());
  const double fall = t.total[peak] - t.total[n - 1];
  rows.push_back({fmt("Fig. 4 (pencil): total peaks inside, at tau=%.3g; fall to tau=10", t.tau[peak]),
                  0.0, fall, 4 * std::hypot(t.total_stderr[peak], t.total_stderr[n - 1]),
                  "must exceed 4 std. errors", peak > 0 && peak < n - 1 &&
                      fall > 4 * std::hypot(t.total_stderr[peak], t.total_stderr[n - 1])});
  const AngularBins bins = t.bins();
  double back = 0, fwd = 0, se = 0;
  const double area = kPiD * kVoxelSphereRadius * kVoxelSphereRadius;
  for (int k = 0; k < p.mu_bins; ++k) {
    const size_t e = size_t(n - 1) * p.mu_bins + k;
    (bins.centre(k) < 0 ? back : fwd) += t.P[e] * bins.solid_angle(k) / area;
    se += t.P_stderr[e] * bins.solid_angle(k) / area;  // an upper bound
  }
  rows.push_back({"Fig. 4 (pencil): tau=10 backward minus forward fraction", 0.0, back - fwd, 4 * se,
                  "must exceed 4 std. errors (summed)", back - fwd > 4 * se});
}

}  // namespace

std::vector<ValidationRow> validate_montecarlo(Backend backend, double effort) {
  std::vector<ValidationRow> rows;
  slab_cases(backend, effort, rows);
  thin_limit_cases(backend, effort, rows);
  conservation_case(backend, effort, rows);
  chi_square_cases(effort, rows);
  figure4_cases(backend, effort, rows);
  return rows;
}

std::vector<BinningRow> compare_binnings(const std::vector<double>& gs, int n_mu, double photons) {
  std::vector<BinningRow> out;
  for (double g : gs) {
    for (AngularBinning kind : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
      // Row 1 (tau = 1) holds the thin-limit expectation tau * bin mean of p_HG.
      ScatteringTable table = ScatteringTable::make_axes(1.0, 2, kind, n_mu);
      table.albedo = 0.6;
      table.g = g;
      table.photons_per_row = static_cast<uint64_t>(photons);
      const AngularBins bins = table.bins();
      std::vector<double> prob(n_mu);
      for (int k = 0; k < n_mu; ++k) {
        const double mean = hg_bin_mean(g, bins.edge(k), bins.edge(k + 1));
        table.P[table.index(1, k)] = static_cast<float>(mean);
        prob[k] = mean * bins.solid_angle(k);  // photons landing in bin k per photon
      }
      const TableView view = view_of(table);
      BinningRow row;
      row.g = g;
      row.binning = kind;
      row.n_mu = n_mu;
      // Uniform in mu is uniform in solid angle.
      const int samples = 20001;
      double err2 = 0, ref2 = 0, noise2 = 0, comb2 = 0;
      for (int s = 0; s < samples; ++s) {
        const double mu = -1.0 + 2.0 * s / (samples - 1);
        const double exact = hg_phase_double(g, mu);
        const double got = view.lookup(1.0f, static_cast<float>(mu));
        const double rel = got / exact - 1;
        err2 += (got - exact) * (got - exact);
        ref2 += exact * exact;
        row.interp_max = std::max(row.interp_max, std::fabs(rel));
        // Relative standard error of the bin holding mu (binomial, thin limit).
        const int k = bins.bin_of(static_cast<float>(mu));
        const double noise = std::sqrt((1 - prob[k]) / (photons * prob[k]));
        noise2 += noise * noise;
        comb2 += rel * rel + noise * noise;
      }
      row.interp_rms = std::sqrt(err2 / ref2);
      row.noise_rms = std::sqrt(noise2 / samples);
      row.combined_rms = std::sqrt(comb2 / samples);
      row.forward_error = view.lookup(1.0f, 1.0f) / hg_phase_double(g, 1.0) - 1;
      out.push_back(row);
    }
  }
  return out;
}

}  // namespace nebula
