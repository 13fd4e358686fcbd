#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/angular_binning.h"
#include "core/device_mirror.h"

namespace nebula {

// P(tau_sct, mu) of DESIGN.md section 3 and everything its file holds
// (section 4). P is the light scattered at least once and leaving a voxel
// sphere of scattering depth tau_sct, per steradian, normalised per voxel
// face area: P = (pi R^2 / l^2) F(mu), so sum_k P_k Omega_k / (pi R^2) is
// the escaped scattered fraction `total`. Row-major [n_tau][n_mu].
struct ScatteringTable {
  // Physics and provenance (file attributes).
  double albedo = 0.0;
  double g = 0.0;
  std::string phase = "henyey-greenstein";
  std::string geometry = "sphere";
  std::string illumination = "parallel";  // or "pencil"
  AngularBinning mu_binning = AngularBinning::UniformMu;
  uint64_t photons_per_row = 0;  // rows of tau_sct >= 1; thinner ones x min(thin_boost, floor(1 / tau_sct))
  uint64_t thin_boost = 1;       // 1 in files written before it existed (no attribute)
  uint64_t seed = 0;
  std::string rng = "philox4x32-10";
  int schema_version = 1;
  std::string generator;  // program and version, e.g. "nebula 0.1.0"

  // Run statistics, kept so a table says how it was made.
  bool forced_first_scattering = false;
  double roulette_threshold = 0.0;
  double roulette_survival = 0.0;
  int max_orders = 0;
  uint64_t capped_photons = 0;     // photons stopped by max_orders
  uint64_t scattering_events = 0;

  // Axes: tau uniform on [0, tau_max] (both ends included); mu_edges and
  // mu are exactly AngularBins::edge and AngularBins::centre.
  std::vector<double> tau;
  std::vector<double> mu_edges;
  std::vector<double> mu;

  // Data, each entry with its Monte-Carlo standard error.
  std::vector<float> P;
  // The CUDA kernels' copy of P, uploaded on first use (core/device_mirror.h;
  // a copy of the table starts without one). P does not change once a
  // renderer reads it.
  mutable DeviceMirror device_P;
  // The device copy of cumulative_rows(*this) (tables/table_lookup.h).
  mutable DeviceMirror device_C;
  std::vector<float> P_stderr;
  std::vector<double> total;
  std::vector<double> total_stderr;
  std::vector<double> unscattered;  // fraction crossing without interaction

  int n_tau() const { return static_cast<int>(tau.size()); }
  int n_mu() const { return static_cast<int>(mu.size()); }
  double tau_max() const { return tau.empty() ? 0.0 : tau.back(); }
  AngularBins bins() const { return AngularBins{mu_binning, n_mu()}; }
  size_t index(int i_tau, int k_mu) const {
    return static_cast<size_t>(i_tau) * mu.size() + static_cast<size_t>(k_mu);
  }

  // A table with its axes filled and every data array zeroed to shape.
  // Throws Error unless tau_max > 0, n_tau >= 2 and n_mu >= 1.
  static ScatteringTable make_axes(double tau_max, int n_tau, AngularBinning binning, int n_mu);

  // total[i] recomputed from row i of P (what check_consistency compares to).
  double total_from_P(int i_tau) const;

  // The median over the entries with P > 0 of P_stderr / P: the relative
  // Monte-Carlo noise an image reading the table carries (0 for an empty table).
  double median_relative_error() const;

  // Throws Error, one line "SOURCE: FIELD: expected ..., found ...", on the
  // first inconsistency; `source` names the file or origin of the table.
  void check_consistency(const std::string& source) const;
};

}  // namespace nebula
