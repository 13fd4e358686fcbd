#pragma once
// The spectral ray marcher (Barrès 2023, Algorithms 3-5, on our grids): the
// exact voxel traversal of the band renderer, each voxel scattering each
// star's light once toward the eye (Henyey-Greenstein, constant albedo a and
// g; the voxel's own extinction left out, DESIGN.md "Ray marching"), with
// the extinction spectral: tau(lambda) = tau_V kappa(lambda). Along a ray
// every voxel-star pair carries a weight w (the star's luminosity, the mean
// 1/r^2 over the chord, a tau_V p_HG(theta) c/l) and one number, its V-band
// optical path D = (star to voxel) + (voxel to eye); its light through filter
// f is w * integral S_f(lambda) kappa(lambda) s_star(lambda) e^(-kappa D) dlambda.
// Four ways to take that integral, all accumulating a few numbers per ray:
//   Double:     M wavelengths per pair (the report's double numerical integral);
//   Analytic:   the closed form of polynomial x e^(-a/lambda) (Algorithm 1) per
//               pair and filter (kappa = C_T / lambda only);
//   Projection: e^(-kappa D) on the greedy basis: N coefficients per pair, per
//               star spectrum accumulated (Algorithms 3-4);
//   LightBasis: s_T e^(-kappa D) on the light-density basis over (D, T): N
//               coefficients per pair, one set of accumulators for all stars
//               (Algorithm 5).
// The filters enter only after the march (resolve): a filter change is a
// small matrix product per pixel, with no new march or bake.
#include <type_traits>

#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "core/math.h"
#include "illumination/chord_irradiance.h"
#include "spectral/expint.h"

namespace nebula::spectral {

enum class SpectralMethod { Double, Analytic, Projection, LightBasis };

constexpr int kMaxAccumulators = 64;  // per ray: registers on the GPU

struct SpectralStarView {
  Vec3 position;
  float power;            // bolometric luminosity, L_sun
  const float* depth_v;   // [voxel] baked V-band depth to the voxel sphere
  float temperature_u;    // LightBasis: the star's coordinate on the table's log T axis
};

struct SpectralSceneView {
  DensityView density;
  const SpectralStarView* stars = nullptr;
  int n_stars = 0;
  float albedo = 0.6f, g = 0.6f;
  float max_eye_depth = 1e30f;  // stop once e^(-kappa_min tau) < min transmittance
  RayFootprint footprint;
  SpectralMethod method = SpectralMethod::Projection;
  int n_acc = 0;  // accumulators per ray (image planes before the resolve)
  // Double: M wavelengths, kappa at each, q[star][acc][i] = S kappa s dlambda.
  int n_lambda = 0;
  const float* kappa = nullptr;
  const float* q = nullptr;
  // Analytic: per star and filter a piecewise polynomial P ~ S s (global powers of lambda, um):
  // the integral is C_T sum_k c_k I_(k-1)(C_T D).
  double C_T = 0;
  const double* breaks = nullptr;        // [star][acc][segments + 1]
  const double* coefficients = nullptr;  // [star][acc][segments][degree + 1]
  int segments = 0, degree = 0;
  // Projection / LightBasis: coefficient tables over D (and log T): [t][d][j].
  int n_basis = 0, n_depth = 0, n_temperature = 1;
  float depth_step = 1;
  const float* coeff = nullptr;
};

// Henyey-Greenstein phase function per steradian.
NEBULA_HD float hg_phase(float mu, float g) {
  const float d = 1.0f + g * g - 2.0f * g * mu;
  return (1.0f - g * g) * kInv4Pi / (d * sqrtf(d));
}

// Adds w times the pair's light in every accumulator (the method a template
// argument, so each kernel holds only its own code).
template <SpectralMethod kMethod>
NEBULA_HD void add_pair(const SpectralSceneView& s, int star, float w, float D, float* acc) {
  switch (kMethod) {
    case SpectralMethod::Double: {
      const float* q = s.q + size_t(star) * s.n_acc * s.n_lambda;
      for (int i = 0; i < s.n_lambda; ++i) {
        const float e = w * expf(-s.kappa[i] * D);
        for (int f = 0; f < s.n_acc; ++f) acc[f] += q[f * s.n_lambda + i] * e;
      }
      break;
    }
    case SpectralMethod::Analytic: {
      const double a = s.C_T * double(D);
      for (int f = 0; f < s.n_acc; ++f) {
        const size_t pf = size_t(star) * s.n_acc + f;
        const double* b = s.breaks + pf * (s.segments + 1);
        const double* c = s.coefficients + pf * s.segments * (s.degree + 1);
        double sum = 0.0;
        for (int seg = 0; seg < s.segments; ++seg)
          for (int k = 0; k <= s.degree; ++k) {
            const double ck = c[seg * (s.degree + 1) + k];
            if (ck != 0.0) sum += ck * power_exp_integral(k - 1, a, b[seg], b[seg + 1]);
          }
        acc[f] += w * float(s.C_T * sum);
      }
      break;
    }
    case SpectralMethod::Projection:
    case SpectralMethod::LightBasis: {
      const float x = D / s.depth_step;
      if (!(x < float(s.n_depth - 1))) break;  // beyond the table: below the transmittance cut
      const int d0 = int(x);
      const float fd = x - float(d0);
      const int N = s.n_basis;
      float* out = s.method == SpectralMethod::Projection ? acc + star * N : acc;
      if (s.method == SpectralMethod::Projection) {
        const float* c0 = s.coeff + size_t(d0) * N;
        for (int j = 0; j < N; ++j) out[j] += w * (c0[j] + fd * (c0[N + j] - c0[j]));
      } else {
        const float u = s.stars[star].temperature_u;
        const int t_last = s.n_temperature > 1 ? s.n_temperature - 2 : 0;
        const int t0 = int(u) < t_last ? int(u) : t_last;
        const float ft = s.n_temperature > 1 ? u - float(t0) : 0.0f;
        const float* c00 = s.coeff + (size_t(t0) * s.n_depth + d0) * N;
        const float* c10 = s.n_temperature > 1 ? c00 + size_t(s.n_depth) * N : c00;
        for (int j = 0; j < N; ++j) {
          const float lo = c00[j] + fd * (c00[N + j] - c00[j]);
          const float hi = c10[j] + fd * (c10[N + j] - c10[j]);
          out[j] += w * (lo + ft * (hi - lo));
        }
      }
      break;
    }
  }
}

// One ray: the accumulators (n_acc of them) before the resolve.
template <SpectralMethod kMethod>
NEBULA_HD void march_spectral(const SpectralSceneView& s, Vec3 origin, Vec3 dir, float* acc) {
  for (int k = 0; k < s.n_acc; ++k) acc[k] = 0.0f;
  const GridShape& g = s.density.shape;
  const Vec3 span = g.upper() - g.origin;
  const float far = length(origin - (g.origin + 0.5f * span)) + length(span) + g.voxel;
  float t_enter = 0.0f, t_exit = 0.0f;
  if (!clip_to_grid(g, origin, dir, far, t_enter, t_exit)) return;
  const float inv_voxel = 1.0f / g.voxel;
  const Vec3 to_eye = -dir;
  float t = t_enter, eye_depth = 0.0f;  // V-band depth from the eye to the current voxel's entry
  traverse_segment_cells(g, origin, origin + far * dir, [&](int, int, int, size_t cell, float chord) -> bool {
    const float tau_v = s.density.tau_v[cell];
    const float fraction = chord * inv_voxel;
    if (tau_v > 0.0f) {
      for (int k = 0; k < s.n_stars; ++k) {
        const ChordIrradiance at = chord_irradiance(origin, dir, t, t + chord, s.stars[k].position, s.footprint);
        const Vec3 d = at.point - s.stars[k].position;
        const float r = length(d);
        const float mu = r > 0.0f ? dot(d, to_eye) / r : 0.0f;
        const float w = s.stars[k].power * kInv4Pi * at.inv_r2 * s.albedo * tau_v * hg_phase(mu, s.g) * fraction;
        add_pair<kMethod>(s, k, w, s.stars[k].depth_v[cell] + eye_depth, acc);
      }
    }
    t += chord;
    eye_depth += tau_v * fraction;
    return eye_depth < s.max_eye_depth;
  });
}

// Calls f(std::integral_constant<SpectralMethod, m>) for the run-time method m.
template <class F>
void dispatch_method(SpectralMethod m, F&& f) {
  switch (m) {
    case SpectralMethod::Double: f(std::integral_constant<SpectralMethod, SpectralMethod::Double>()); break;
    case SpectralMethod::Analytic: f(std::integral_constant<SpectralMethod, SpectralMethod::Analytic>()); break;
    case SpectralMethod::Projection: f(std::integral_constant<SpectralMethod, SpectralMethod::Projection>()); break;
    case SpectralMethod::LightBasis: f(std::integral_constant<SpectralMethod, SpectralMethod::LightBasis>()); break;
  }
}

}  // namespace nebula::spectral
