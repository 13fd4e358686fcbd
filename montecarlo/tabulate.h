#pragma once
// The Monte-Carlo tabulator of P(tau_sct, mu) for one voxel (2005 paper,
// section 4.1), on the CPU (TBB) or the GPU (CUDA).
#include <cstdint>
#include <string>
#include <vector>

#include "core/angular_binning.h"
#include "core/backend.h"
#include "montecarlo/voxel_sphere.h"

namespace nebula {

class Progress;

// Photons per row (thin rows' boost included) stay below this so that a photon
// index fits Philox's 32-bit counter word and fixed-point sums cannot overflow.
constexpr uint64_t kMaxPhotonsPerRow = uint64_t(1) << 30;
constexpr int kMaxMuBins = 8192;
constexpr int kMaxThinBoost = 1024, kDefaultThinBoost = 32;
// The most photons per row a table with the default thin_boost may ask for.
constexpr uint64_t kMaxBasePhotons = kMaxPhotonsPerRow / kDefaultThinBoost;

struct TabulateParams {
  double albedo = 0.6;
  double g = 0.6;
  double tau_max = 10.0;  // largest tau_sct per voxel edge
  int tau_bins = 1000;    // rows, uniform from 0 to tau_max inclusive
  AngularBinning binning = AngularBinning::UniformMu;
  int mu_bins = 72;
  uint64_t photons_per_row = 1000000;
  // Rows of tau_sct < 1 get more photons: photons_per_row x min(thin_boost,
  // floor(1 / tau_sct)) (photons_of_row). A thin row's photons are cheap (one
  // or two events each) and its bins far from the forward peak see few of
  // them: at g = 0.9 and 3e4 photons their noise was the largest error of the
  // renders of a back-lit layer (docs/tabulator.md, "Photons per row"). 1: the
  // same count in every row.
  int thin_boost = kDefaultThinBoost;
  uint64_t seed = 1;
  Beam beam = Beam::Parallel;
  bool forced_first_scattering = true;
  Roulette roulette;
};


// Throws ParameterError naming the field of the first bad parameter.
void validate(const TabulateParams& p);

double tau_of_row(const TabulateParams& p, int row);
// Photons traced in row `row` (thin_boost above).
uint64_t photons_of_row(const TabulateParams& p, int row);
// Their sum over the rows.
uint64_t photons_of_table(const TabulateParams& p);

// Everything a photon of table row `row` needs (host-built, passed to kernels).
SphereRow make_sphere_row(const TabulateParams& p, int row);
// Largest weight a photon of that row can carry; tallies are divided by it.
double weight_scale(const TabulateParams& p, int row);

// Exact 32.32 fixed-point sums per row, as both backends produce them.
struct SphereTallies {
  int n_tau = 0, n_mu = 0;
  std::vector<uint64_t> sum_w, sum_w2;  // [n_tau][n_mu], weight / weight_scale
  std::vector<uint64_t> unscattered;    // [n_tau], weight leaving unscattered
  std::vector<uint64_t> events;         // [n_tau], scattering events
  std::vector<uint64_t> capped;         // [n_tau], photons stopped by the order cap
  std::vector<uint64_t> capped_weight;  // [n_tau], their weight / weight_scale
  double compute_seconds = 0;           // transport only (CUDA events on the GPU)
  void resize(int tau, int mu);
};

struct Tabulation {
  TabulateParams params;
  std::vector<double> tau;                 // [n_tau]
  std::vector<double> P, P_stderr;         // [n_tau][n_mu], per steradian per face area
  std::vector<double> total, total_stderr; // [n_tau], scattered fraction that escapes
  std::vector<double> unscattered;         // [n_tau], fraction leaving unscattered
  uint64_t scattering_events = 0;
  uint64_t capped_photons = 0;
  double capped_weight = 0;  // largest per-row fraction of incident light lost to the cap
  double seconds = 0;          // end to end, allocation and copies included
  double compute_seconds = 0;  // photon transport alone
  std::string device;
  AngularBins bins() const { return {params.binning, params.mu_bins}; }
  int n_tau() const { return params.tau_bins; }
  int n_mu() const { return params.mu_bins; }
};

// Converts tallies into P, its standard errors and the totals.
Tabulation finish_tabulation(const TabulateParams& p, const SphereTallies& t);

// Runs the tabulation; progress (may be null) is advanced in photons.
Tabulation tabulate(const TabulateParams& p, Backend backend, Progress* progress = nullptr);

// Backend entry points (the CUDA one throws Error when built without CUDA).
SphereTallies tabulate_sphere_cpu(const TabulateParams& p, Progress* progress);
SphereTallies tabulate_sphere_cuda(const TabulateParams& p, Progress* progress);

}  // namespace nebula
