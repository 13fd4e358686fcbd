#pragma once
// Henyey-Greenstein phase function (Henyey & Greenstein 1941, ApJ 93, 70):
// evaluation, float32-safe sampling and the direction update.
#include <cmath>

#include "core/hd.h"
#include "core/math.h"
#include "core/vec3.h"

namespace nebula {

// Below this |g| the inversion formula loses float32 precision (its error
// grows like 1.2e-7/|g|), and HG differs from isotropic by at most 3|g|: sample
// isotropically there.
constexpr float kHgIsotropicBelow = 1e-3f;

// Phase function per steradian, normalised over 4 pi; mu = cos(theta).
// 1 + g^2 - 2 g mu is written around the peak, (1 - |g|)^2 + 2|g|(1 -+ mu),
// so that it keeps its precision (and stays positive) as |g| -> 1 near the peak.
// Its -3/2 power by one reciprocal square root, no division: the spectral
// march takes it per voxel and star.
NEBULA_HD float hg_phase(float g, float mu) {
  const float h = fabsf(g), q = g >= 0.0f ? 1.0f - mu : 1.0f + mu;
  const float denom = (1.0f - h) * (1.0f - h) + 2.0f * h * q;
  const float r = reciprocal_sqrt(denom);
  return kInv4Pi * (1.0f - h) * (1.0f + h) * (r * r * r);
}

// A sampled deflection: cosine and sine of the polar angle. Both are kept
// because float32 cannot hold the cosine of strongly forward-peaked dust
// (g = 0.99 puts 2% of the light within 1 - mu < 2e-8, below float32's
// spacing at 1), while the sine, computed from 1 - |mu| directly, stays exact
// to rounding and steers the direction update.
struct HgSample {
  float cos_theta;
  float sin_theta;
};

// HG deflection for xi uniform in (0, 1). |g| < 1 is the caller's promise
// (parameters are validated on the host). Writing 1 - mu in closed form avoids
// the cancellation of the textbook inversion; every denominator is at least
// 1 - |g| > 0 and the result is clamped, so no NaN reaches the direction update.
// A negative g samples |g| and mirrors: HG(g, mu) = HG(-g, -mu).
NEBULA_HD HgSample hg_sample(float g, float xi) {
  const float h = fabsf(g);
  if (h < kHgIsotropicBelow) return {1.0f - 2.0f * xi, 2.0f * sqrtf(xi * (1.0f - xi))};
  const float denom = 1.0f - h + 2.0f * h * xi;
  const float s = (1.0f - h) * (1.0f + h) / denom;
  // t = 1 - mu for asymmetry h, from s - (1 - h) = 2h (1 - h)(1 - xi) / denom.
  const float t = clamp((1.0f - h) * (1.0f - xi) * (s + 1.0f - h) / denom, 0.0f, 2.0f);
  const float mu = 1.0f - t;
  return {g < 0.0f ? -mu : mu, sqrtf(t * (2.0f - t))};
}

NEBULA_HD void sin_cos_2pi(float xi, float& s, float& c) {
#if NEBULA_ON_DEVICE
  sincospif(2.0f * xi, &s, &c);
#else
  s = sinf(2.0f * kPi * xi);
  c = cosf(2.0f * kPi * xi);
#endif
}

// Turns unit vector d by the polar angle (cos, sin) and the azimuth whose
// sine and cosine are given. The frame is built around d (no pole branch),
// and the result renormalised.
NEBULA_HD Vec3 scatter_direction(Vec3 d, HgSample angle, float sin_phi, float cos_phi) {
  Vec3 t, b;
  orthonormal_frame(d, t, b);
  return normalize((angle.sin_theta * cos_phi) * t + (angle.sin_theta * sin_phi) * b +
                   angle.cos_theta * d);
}

// Host-side exact results, in double, for tests and validation.
// Cumulative distribution P(mu' <= mu) from integrating hg_phase over the
// azimuth and from -1 to mu.
inline double hg_cdf(double g, double mu) {
  if (g == 0.0) return 0.5 * (mu + 1.0);
  return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * mu) - 1.0 / (1.0 + g));
}

// Mean of the phase function per steradian over mu in [mu0, mu1].
inline double hg_bin_mean(double g, double mu0, double mu1) {
  return (hg_cdf(g, mu1) - hg_cdf(g, mu0)) / (2.0 * kPiD * (mu1 - mu0));
}

inline double hg_phase_double(double g, double mu) {
  const double denom = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPiD * denom * std::sqrt(denom));
}

}  // namespace nebula
