#pragma once
#include <cmath>
#include <string>

#include "core/hd.h"
#include "core/math.h"

namespace nebula {

// How the scattering angle is binned: uniform in mu = cos(theta) (the 2005
// paper's choice) or uniform in theta, which resolves forward-peaked phase
// functions better at the same bin count. Edges ascend in mu from -1 to 1 in
// both cases, so bin 0 is backward scattering.
enum class AngularBinning : int { UniformMu = 0, UniformTheta = 1 };

struct AngularBins {
  AngularBinning kind = AngularBinning::UniformMu;
  int n = 72;

  // Continuous bin coordinate: bin k spans [k, k + 1), its centre sits at k + 1/2.
  NEBULA_HD float position(float mu) const {
    mu = clamp(mu, -1.0f, 1.0f);
    if (kind == AngularBinning::UniformMu) return 0.5f * (mu + 1.0f) * n;
    return (1.0f - acosf(mu) * (1.0f / kPi)) * n;
  }
  NEBULA_HD int bin_of(float mu) const {
    const int k = static_cast<int>(floorf(position(mu)));
    return k < 0 ? 0 : (k >= n ? n - 1 : k);
  }
  // Lower edge of bin k in mu (k = n gives the upper edge, 1).
  double edge(int k) const {
    if (k <= 0) return -1.0;
    if (k >= n) return 1.0;
    if (kind == AngularBinning::UniformMu) return -1.0 + 2.0 * k / n;
    return -std::cos(kPiD * k / n);
  }
  // The bin centre in the binned variable, expressed as mu.
  double centre(int k) const {
    if (kind == AngularBinning::UniformMu) return -1.0 + (2.0 * k + 1.0) / n;
    return -std::cos(kPiD * (k + 0.5) / n);
  }
  double solid_angle(int k) const { return 2.0 * kPiD * (edge(k + 1) - edge(k)); }
};

inline const char* to_string(AngularBinning b) {
  return b == AngularBinning::UniformMu ? "uniform-mu" : "uniform-theta";
}

// Parses "uniform-mu"/"mu" or "uniform-theta"/"theta"; returns false otherwise.
inline bool parse_angular_binning(const std::string& s, AngularBinning& out) {
  if (s == "uniform-mu" || s == "mu") {
    out = AngularBinning::UniformMu;
    return true;
  }
  if (s == "uniform-theta" || s == "theta") {
    out = AngularBinning::UniformTheta;
    return true;
  }
  return false;
}

}  // namespace nebula
