#pragma once
// The tabulator's validation suite against exact results, shared by
// `nebula validate montecarlo` and validation_tests.
#include <string>
#include <vector>

#include "core/angular_binning.h"
#include "core/backend.h"

namespace nebula {

struct ValidationRow {
  std::string check;     // what is compared
  double expected = 0;   // exact or published value
  double measured = 0;
  double tolerance = 0;  // the bound |measured - expected| must stay within
  std::string basis;     // where the tolerance comes from
  bool pass = false;
};

// Runs every case; `effort` scales the photon counts (1 = the documented set).
std::vector<ValidationRow> validate_montecarlo(Backend backend, double effort = 1.0);

// How well a table of n_mu bins represents a phase function: the thin-limit
// table (exact bin means of p_HG) interpolated as the renderer does, against
// p_HG itself, and the Monte-Carlo noise its bins would carry.
struct BinningRow {
  double g = 0;
  AngularBinning binning = AngularBinning::UniformMu;
  int n_mu = 0;
  double interp_rms = 0;    // relative L2 error over the sphere
  double interp_max = 0;    // largest relative error over mu
  double forward_error = 0; // relative error at theta = 0
  double noise_rms = 0;     // relative MC noise, solid-angle RMS, at `photons`
  double combined_rms = 0;  // sqrt(interp^2 + noise^2), solid-angle RMS
};
std::vector<BinningRow> compare_binnings(const std::vector<double>& gs, int n_mu, double photons);

}  // namespace nebula
