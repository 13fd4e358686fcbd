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
//   VoxelLight: a per-view pre-pass sums every star's light per voxel, so the
//               march's cost per voxel does not grow with the stars. The pair's
//               integral splits as integral S_f kappa s e^(-kappa D_star)
//               e^(-kappa D_eye); only e^(-kappa D_eye) is projected on the
//               greedy basis (c_j(D_eye), the projection's table), and
//               Q_fj(star, D_star) = integral S_f kappa s e^(-kappa D_star) phi_j
//               is tabulated per star (exact in D_star). The pre-pass stores per
//               voxel U_fj = sum over stars of w Q_fj at the voxel's centre and
//               its gradient (w's 1/r^2 and phase vary across the voxel); the
//               march adds fraction * sum_j c_j(D_eye) U_fj(chord midpoint) per
//               filter: F accumulators, F N multiply-adds per voxel for any
//               number of stars. Pairs of a voxel within `near_distance` of a
//               star (1/r^2 not smooth there) are taken exactly in the march,
//               as the other methods do (docs/spectral.md, "Voxel light").
// The filters enter only after the march (resolve): a filter change is a
// small matrix product per pixel, with no new march or bake.
#include <type_traits>

#include "core/camera.h"
#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "core/math.h"
#include "illumination/chord_irradiance.h"
#include "spectral/expint.h"

namespace nebula::spectral {

enum class SpectralMethod { Double, Analytic, Projection, LightBasis, VoxelLight };

constexpr int kMaxAccumulators = 64;  // per ray: registers on the GPU
constexpr int kMaxBasis = 16;
constexpr int kMaxVoxelLightStars = 32;  // VoxelLight: one bit per star in a voxel's near-star mask

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
  // VoxelLight (n_acc = filters F): star_coeff[star][d][f][j] = Q_fj(star, D_d) on the
  // coeff table's depths; voxel_light[cell][4][F N] the pre-pass' U at the voxel's
  // centre and its x, y, z derivatives; near_stars[cell] bit k: star k's pair is
  // taken exactly (the voxel's centre within near_distance of the star).
  const float* star_coeff = nullptr;
  const float* voxel_light = nullptr;
  const unsigned* near_stars = nullptr;
  float near_distance = 0;
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
    case SpectralMethod::VoxelLight:
      break;  // summed per voxel ahead of the march (voxel_light)
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

// VoxelLight: the coefficients of the table at depth D (false beyond it).
NEBULA_HD bool depth_coefficients(const SpectralSceneView& s, const float* table, int width, float D, float* out) {
  const float x = D / s.depth_step;
  if (!(x < float(s.n_depth - 1))) return false;
  const int d0 = int(x);
  const float fd = x - float(d0);
  const float* c0 = table + size_t(d0) * width;
  for (int i = 0; i < width; ++i) out[i] = c0[i] + fd * (c0[width + i] - c0[i]);
  return true;
}

// VoxelLight: star k's row of Q_fj at its depth to `cell`, interpolated as
// row[i] + fd (row[F N + i] - row[i]); null beyond the table.
NEBULA_HD const float* star_integrals(const SpectralSceneView& s, int k, size_t cell, float& fd) {
  const float x = s.stars[k].depth_v[cell] / s.depth_step;
  if (!(x < float(s.n_depth - 1))) return nullptr;
  const int d0 = int(x);
  fd = x - float(d0);
  return s.star_coeff + (size_t(k) * s.n_depth + d0) * (s.n_acc * s.n_basis);
}

// u[4][FN] += (w, grad) times the star's row q interpolated at fd (restrict:
// the table and the voxel's light never overlap, so the loop vectorises). The
// same sums, in the same order, as the GPU's per-output loop below.
NEBULA_HD void add_star_light(float* __restrict__ u, const float* __restrict__ q, int FN, float fd, float w, Vec3 grad) {
  for (int i = 0; i < FN; ++i) {
    const float v = q[i] + fd * (q[FN + i] - q[i]);
    u[i] += w * v;
    u[FN + i] += grad.x * v;
    u[2 * FN + i] += grad.y * v;
    u[3 * FN + i] += grad.z * v;
  }
}

// VoxelLight's per-view pre-pass for voxels x0 .. x0 + kRow - 1 (those below
// the grid's edge) of row (y, z): U = a tau_V sum_k L_k/(4 pi r^2) p_HG(mu)
// Q(star k, D_k) at each voxel's centre and its gradient (analytic: 1/r^2 and
// mu, with the direction to the eye varying across the voxel as the rays
// through it do), into light[cell][4][F N]; near[cell] bit k: star k's pair
// taken exactly in the march instead. Cost: voxels x stars, once per view.
// First each star's weight and gradient per voxel (kRow voxels side by side,
// branch-free: vectorised on the CPU), then the sums over the stars. The CPU
// runs rows of 16 voxels, the GPU one voxel per thread (kRow 1), summing each
// output in registers and writing it once (no read-modify-write per star in
// global memory).
template <int kRow>
NEBULA_HD void voxel_light(const SpectralSceneView& s, const Camera& camera, int x0, int y, int z, float* light,
                           unsigned* near) {
  const GridShape& g = s.density.shape;
  const int n = g.nx - x0 < kRow ? g.nx - x0 : kRow;
  const size_t cell0 = g.index(x0, y, z);
  const int FN = s.n_acc * s.n_basis;
  const Vec3 c0 = g.centre(x0, y, z);
  float ex[kRow], ey[kRow], ez[kRow], inv_rho[kRow], tau[kRow];
  for (int i = 0; i < n; ++i) {
    const Vec3 centre{c0.x + float(i) * g.voxel, c0.y, c0.z};
    const Vec3 e = camera.to_eye(centre);
    ex[i] = e.x;
    ey[i] = e.y;
    ez[i] = e.z;
    // 1 / distance to the eye: the rays' direction turns by (offset / distance) across the voxel.
    const float rho = length(camera.position - centre);
    inv_rho[i] = camera.projection == Projection::Orthographic || !(rho > 0.0f) ? 0.0f : 1.0f / rho;
    tau[i] = s.density.tau_v[cell0 + i];
  }
  const float near2 = 0.5f * s.near_distance * s.near_distance, g2 = s.g * s.g;
  const float phase_norm = (1.0f - g2) * kInv4Pi * s.albedo, inv_step = 1.0f / s.depth_step;
  const float last = float(s.n_depth - 1);
  // Per star and voxel: weight, its gradient, the table position; the near mask.
  float w[kMaxVoxelLightStars][kRow], gx[kMaxVoxelLightStars][kRow], gy[kMaxVoxelLightStars][kRow],
      gz[kMaxVoxelLightStars][kRow], xd[kMaxVoxelLightStars][kRow], is_near[kMaxVoxelLightStars][kRow];
  for (int k = 0; k < s.n_stars; ++k) {
    const Vec3 star = s.stars[k].position;
    const float* depth = s.stars[k].depth_v + cell0;
    const float power = s.stars[k].power * kInv4Pi * phase_norm;
    for (int i = 0; i < n; ++i) {  // branch-free: arithmetic and masks, no early exits
      const float dx = c0.x + float(i) * g.voxel - star.x, dy = c0.y - star.y, dz = c0.z - star.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      const float inv_r = 1.0f / sqrtf(r2 + 1e-30f);
      const float hx = dx * inv_r, hy = dy * inv_r, hz = dz * inv_r;
      const float mu = hx * ex[i] + hy * ey[i] + hz * ez[i];
      // The expansion's error is second order, (offset / r)^2 times the curvature of ln w
      // in the angle seen from the star: 2 for 1/r^2, plus the phase's |d^2 ln p / d theta^2|
      // (3g / (1 - g)^2 in forward scattering: 11 at g = 0.6). near_distance holds for
      // the curvature 2 of 1/r^2 alone; a sharper phase widens it as the square root.
      const float A = 1.0f + g2 - 2.0f * s.g * mu, inv_A = 1.0f / A;
      const float curvature = 2.0f + fabsf(3.0f * s.g * (mu * A - 2.0f * s.g * (1.0f - mu * mu))) * inv_A * inv_A;
      const float lit = tau[i] > 0.0f ? 1.0f : 0.0f;
      const float close = r2 < near2 * curvature ? lit : 0.0f;
      const float x = depth[i] * inv_step;
      // Products of 0/1 flags, not &&: no branch (beyond the table: below the transmittance cut).
      const float take = (lit - close) * (x < last ? 1.0f : 0.0f);
      // r^2 softened by the pixel's footprint at the star, as chord_irradiance does (a ray
      // stands for its pixel): 1 / (r^2 + w^2 / (4 pi)).
      const float t_star = (camera.position.x - star.x) * ex[i] + (camera.position.y - star.y) * ey[i] +
                           (camera.position.z - star.z) * ez[i];
      const float width = s.footprint.width_at_eye + 0.5f * (t_star + fabsf(t_star)) * s.footprint.spread;
      const float inv_r2 = 1.0f / (r2 + width * width * kInv4Pi);
      const float wi = power * tau[i] * inv_r2 * inv_A * sqrtf(inv_A) * take;
      // grad ln w = -2 d / r2 + (d ln p / d mu) grad mu, grad mu = (e - mu h) / r - (h - mu e) / rho.
      const float a = -2.0f * inv_r2, b = 3.0f * s.g * inv_A;
      gx[k][i] = wi * (a * dx + b * (inv_r * (ex[i] - mu * hx) - inv_rho[i] * (hx - mu * ex[i])));
      gy[k][i] = wi * (a * dy + b * (inv_r * (ey[i] - mu * hy) - inv_rho[i] * (hy - mu * ey[i])));
      gz[k][i] = wi * (a * dz + b * (inv_r * (ez[i] - mu * hz) - inv_rho[i] * (hz - mu * ez[i])));
      w[k][i] = wi;
      xd[k][i] = x * take;
      is_near[k][i] = close;
    }
  }
  for (int i = 0; i < n; ++i) {
    float* u = light + (cell0 + i) * 4 * FN;
    if constexpr (kRow == 1) {  // GPU: each output summed over the stars in registers, written once
      for (int j = 0; j < FN; ++j) {
        float a0 = 0.0f, a1 = 0.0f, a2 = 0.0f, a3 = 0.0f;
        for (int k = 0; k < s.n_stars; ++k) {
          if (w[k][i] == 0.0f) continue;
          const int d0 = int(xd[k][i]);
          const float* q = s.star_coeff + (size_t(k) * s.n_depth + d0) * FN + j;
          const float v = q[0] + (xd[k][i] - float(d0)) * (q[FN] - q[0]);
          a0 += w[k][i] * v;
          a1 += gx[k][i] * v;
          a2 += gy[k][i] * v;
          a3 += gz[k][i] * v;
        }
        u[j] = a0;
        u[FN + j] = a1;
        u[2 * FN + j] = a2;
        u[3 * FN + j] = a3;
      }
    } else {  // CPU: star by star, the outputs contiguous (vectorised; the voxel's light stays in cache)
      for (int j = 0; j < 4 * FN; ++j) u[j] = 0.0f;
      for (int k = 0; k < s.n_stars; ++k) {
        if (w[k][i] == 0.0f) continue;
        const int d0 = int(xd[k][i]);
        add_star_light(u, s.star_coeff + (size_t(k) * s.n_depth + d0) * FN, FN, xd[k][i] - float(d0), w[k][i],
                       Vec3{gx[k][i], gy[k][i], gz[k][i]});
      }
    }
    unsigned mask = 0;
    for (int k = 0; k < s.n_stars; ++k) mask |= unsigned(is_near[k][i] != 0.0f) << k;
    near[cell0 + i] = mask;
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
  traverse_segment_cells(g, origin, origin + far * dir, [&](int ix, int iy, int iz, size_t cell, float chord) -> bool {
    const float tau_v = s.density.tau_v[cell];
    const float fraction = chord * inv_voxel;
    if constexpr (kMethod == SpectralMethod::VoxelLight) {
      float c[kMaxBasis];
      if (tau_v > 0.0f && depth_coefficients(s, s.coeff, s.n_basis, eye_depth, c)) {
        const int F = s.n_acc, N = s.n_basis, FN = F * N;
        const float* u = s.voxel_light + cell * 4 * FN;
        const Vec3 delta = origin + (t + 0.5f * chord) * dir - g.centre(ix, iy, iz);
        for (int f = 0; f < F; ++f) {
          float sum = 0.0f;
          for (int j = 0; j < N; ++j) {
            const int i = f * N + j;
            sum += c[j] * (u[i] + delta.x * u[FN + i] + delta.y * u[2 * FN + i] + delta.z * u[3 * FN + i]);
          }
          acc[f] += fraction * sum;
        }
        for (unsigned near = s.near_stars[cell]; near != 0u; near &= near - 1u) {
          int k = 0;
          while (!((near >> k) & 1u)) ++k;
          float fd = 0.0f;
          const float* q = star_integrals(s, k, cell, fd);
          if (!q) continue;
          const ChordIrradiance at = chord_irradiance(origin, dir, t, t + chord, s.stars[k].position, s.footprint);
          const Vec3 d = at.point - s.stars[k].position;
          const float r = length(d);
          const float mu = r > 0.0f ? dot(d, to_eye) / r : 0.0f;
          const float w = s.stars[k].power * kInv4Pi * at.inv_r2 * s.albedo * tau_v * hg_phase(mu, s.g) * fraction;
          for (int f = 0; f < F; ++f) {
            float sum = 0.0f;
            for (int j = 0; j < N; ++j) {
              const int i = f * N + j;
              sum += c[j] * (q[i] + fd * (q[FN + i] - q[i]));
            }
            acc[f] += w * sum;
          }
        }
      }
    } else if (tau_v > 0.0f) {
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
    case SpectralMethod::VoxelLight: f(std::integral_constant<SpectralMethod, SpectralMethod::VoxelLight>()); break;
  }
}

}  // namespace nebula::spectral
