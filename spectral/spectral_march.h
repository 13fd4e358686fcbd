#pragma once
// The spectral ray marcher (Barrès 2023, Algorithms 3-5, on our grids): the
// exact voxel traversal of the band renderer, each voxel scattering each
// star's light toward the eye (Henyey-Greenstein, constant albedo a and g; the
// voxel's own extinction left out, DESIGN.md "Ray marching"), with the
// extinction spectral: tau(lambda) = tau_V kappa(lambda). Along a ray every
// voxel-star pair carries a weight w (the star's luminosity, the mean 1/r^2
// over the chord, a tau_V p_HG(theta) c/l) and one number, its V-band optical
// path D = (star to voxel) + (voxel to eye); in the thin-voxel limit its light
// through filter f is w * integral S_f(lambda) kappa(lambda) s_star(lambda)
// e^(-kappa D) dlambda. With the voxel's scattering table (multiple scattering
// inside it) P(a tau_V kappa, theta) replaces a tau_V kappa p_HG: read at a few
// attenuations and taken as a polynomial in kappa between them, each power of
// kappa one more term of the same form (SpectralSceneView::n_nodes,
// pair_weights; docs/spectral.md, "Tables").
// Five ways to take that integral, all accumulating a few numbers per ray:
//   Double:     M wavelengths per pair (the report's double numerical integral);
//   Analytic:   the closed form of polynomial x e^(-a/lambda) (Algorithm 1) per
//               pair and filter (kappa = C_T / lambda only);
//   Projection: e^(-kappa D) on the greedy basis: N coefficients per pair, per
//               star spectrum accumulated (Algorithms 3-4);
//   LightBasis: s_T e^(-kappa D) on the light-density basis over (D, T): N
//               coefficients per pair, one set of accumulators for all stars
//               (Algorithm 5).
//   Preintegrated: the whole integral S_f kappa s e^(-kappa D) tabulated per
//               star and filter over D (pre-integration, the report's section
//               4.4 as we read it): one lookup per pair and filter, no basis;
//               a filter change rebuilds the tables and re-runs the march.
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
#include "montecarlo/henyey_greenstein.h"
#include "spectral/expint.h"
#include "tables/chord_phase.h"
#include "tables/table_lookup.h"

namespace nebula::spectral {

enum class SpectralMethod { Double, Analytic, Projection, LightBasis, VoxelLight, Preintegrated };

constexpr int kMaxAccumulators = 64;  // per ray: registers on the GPU
constexpr int kMaxBasis = 16;
constexpr int kMaxVoxelLightStars = 32;  // VoxelLight: one bit per star in a voxel's near-star mask
constexpr int kMaxTableNodes = 4;        // attenuations at which a pair reads the table
constexpr int kMaxEmission = 8;          // emission components
constexpr int kMaxEmissionPlanes = 32;   // emission numbers per ray
constexpr int kAnalyticTerms = 4;        // Analytic: coefficients of a cubic (piecewise_polynomial.h)

// One emission component in the march (add_emission): its weight per voxel
// (null: the voxel's tau_V) times scale, and its first plane among the
// emission's (after the n_acc star planes).
struct SpectralEmissionView {
  const float* weight = nullptr;
  float scale = 1;
  int plane = 0;
  bool line = false;
  float line_kappa = 0;  // a line's attenuation kappa(lambda_l)
};

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
  // Analytic: per star and filter a piecewise cubic P ~ S s (global powers of lambda, um) on
  // breaks shared by all (every filter's measured rows, where S is exactly linear, a tabulated
  // star's, a continuum's ends): the integral of P kappa e^(-kappa D), kappa = C_T / lambda, is
  // C_T sum_j sum_k jump_jk F_(k-1)(b_j), F the antiderivatives at the break (expint.h) and
  // jump_jk = c_(j-1)k - c_jk the change of P's coefficients there. One chain of F per break
  // serves every filter, star, power and segment end.
  double C_T = 0;
  const double* breaks = nullptr;       // [n_breaks], um ascending
  const double* jumps = nullptr;        // [star][acc][n_breaks][kAnalyticTerms]
  const int* break_range = nullptr;     // [acc][2]: the filter's first and last break
  int n_breaks = 0, break_lo = 0, break_hi = -1;  // the breaks any filter uses
  // Projection / LightBasis: coefficient tables over D (and log T): [t][d][j].
  int n_basis = 0, n_depth = 0, n_temperature = 1;
  float depth_step = 1, inv_depth_step = 1;  // a depth's row is D * inv_depth_step: no division per pair
  const float* coeff = nullptr;
  // Preintegrated (n_acc = filters F): star_coeff[star][p][d][f] = the integral over
  // lambda of S_f kappa (kappa - kappa_c)^p s e^(-kappa D_d) (VoxelLight's Q with the
  // one element phi = 1: n_basis 1); emission_coeff[component][d][f] that of S_f phi
  // e^(-kappa D_d) for a continuum.
  // VoxelLight (n_acc = filters F): star_coeff[star][d][f][j] = Q_fj(star, D_d) on the
  // coeff table's depths; voxel_light[cell][4][F N] the pre-pass' U at the voxel's
  // centre and its x, y, z derivatives; near_stars[cell] bit k: star k's pair is
  // taken exactly (the voxel's centre within near_distance of the star).
  const float* star_coeff = nullptr;
  const float* voxel_light = nullptr;
  const unsigned* near_stars = nullptr;
  float near_distance = 0;
  // The voxel's scattering table (docs/spectral.md, "Tables"). n_nodes = 0: the
  // thin-voxel limit P = tau_sct p_HG. Else P(a tau_V kappa, mu), which holds the
  // multiple scattering inside the voxel, is read at the attenuations
  // node_kappa[m], and P / kappa is interpolated in kappa by the polynomial
  // sum_p B_p (kappa - kappa_c)^p through them (B_p = sum_m node_to_power[p][m] P_m /
  // kappa_m): the pair's light is then sum_p B_p integral S_f kappa (kappa - kappa_c)^p s
  // e^(-kappa D) dlambda, and each power p has its own block of the coefficient
  // tables (coeff, star_coeff: n_powers blocks, the model's). Double reads P at
  // each of its wavelengths instead (the reference the nodes are measured against).
  TableView table;
  int n_nodes = 0;
  int n_powers = 1;
  float kappa_center = 0;  // the powers are of kappa - kappa_center (SpectralModel)
  float node_kappa[kMaxTableNodes] = {};
  float node_to_power[kMaxTableNodes * kMaxTableNodes] = {};
  // node_to_power[q][m] / node_kappa[m]: B_q = sum_m node_weight[q][m] P_m, with no division per pair.
  float node_weight[kMaxTableNodes * kMaxTableNodes] = {};
  // Emission (docs/spectral.md, "Emission"): a voxel adds w(x) phi(lambda) seen
  // through e^(-kappa D_eye), D_eye the V-band depth from the eye to its entry.
  // A line's plane gathers w e^(-kappa_l D) (exact; resolved with S_f(lambda_l));
  // a continuum's planes: Double, per filter sum_i emission_q e^(-kappa_i D);
  // Analytic, per filter the closed form of S_f phi e^(-C_T D / lambda) from
  // the emission's piecewise cubics; the basis methods, per element c_j(D) of
  // e^(-kappa D) (emission_coeff [d][j]), resolved with integral S_f phi b_j.
  int n_emission = 0, n_emission_planes = 0;
  SpectralEmissionView emission[kMaxEmission];
  const float* emission_q = nullptr;               // Double: [component][filter][lambda]
  const double* emission_jumps = nullptr;          // Analytic: [component][filter][n_breaks][kAnalyticTerms]
  const float* emission_coeff = nullptr;           // basis methods: [d][j]
  // Light scattered between voxels (docs/spectral.md, "Light between voxels"),
  // from the band renderer's diffuse field baked star by star at the nodes'
  // attenuations: diffuse[(cell * n_stars + k) * (n_nodes + 1) + ...] = the
  // weights B_p of star k's light in the voxel on the powers of kappa - kappa_c
  // (n_nodes) and their depth D_d: the voxel adds L_k (c/l) sum_p B_p integral
  // S_f kappa (kappa - kappa_c)^p s_k e^(-kappa (D_eye + D_d)) dlambda, a pair of
  // star k's at optical path D_eye + D_d. eye_tau[cell]: the voxel's V-band
  // depth as the eye sees through it, the field's forward peak taken out
  // (diffuse_eye_depth). Null: none.
  const float* diffuse = nullptr;
  const float* eye_tau = nullptr;
  // Albedo and g varying with wavelength (SpectralSettings::curve_*;
  // docs/spectral.md): node m scatters with (node_albedo[m], node_g[m]) through
  // its own table node_P[m] (the axes are `table`'s), or in the thin-voxel limit
  // a kappa tau p_HG where there are no tables (node_P null); albedo and g above
  // are then only the reference the pair's weight w is made with. Double (thin
  // limit only) takes them at each wavelength: lambda_albedo[i], lambda_g[i].
  bool varying = false;
  float node_albedo[kMaxTableNodes] = {}, node_g[kMaxTableNodes] = {};
  const float* node_P[kMaxTableNodes] = {};
  const float* node_C[kMaxTableNodes] = {};  // their cumulative rows (TableView::C; null: the midpoint only)
  // Every node's table value at once (node_table_values): node_table[(row * n_mu + bin) * 4 + m] =
  // node m's lookup at its scattering depth for tau_V = row / node_table_inv_step, at the bin's
  // centre; one bilinear read of 16-byte cells for all nodes instead of one lookup per node.
  // Null: a lookup per node (and always for a chord's mean near a star). use_node_table sets them.
  const float* node_table = nullptr;
  int node_table_rows = 0;
  float node_table_inv_step = 1;  // rows per unit of tau_V
  // Rays within this distance of a star (by their direction: NearStarRadius) take the phase's
  // mean over their chords' angles (march_spectral<kMethod, true>; tables/chord_phase.h); 0:
  // none (the thin limit, uniform-mu tables).
  NearStarRadius near_star_radius;
  const float* lambda_albedo = nullptr;
  const float* lambda_g = nullptr;
};

// A depth D's place on the star tables' depth axis (steps of depth_step): the
// row d0 below it and the fraction fd to the next; false beyond the last row,
// where the light is below the transmittance cut.
NEBULA_HD bool depth_row(const SpectralSceneView& s, float D, int& d0, float& fd) {
  const float x = D * s.inv_depth_step;
  if (!(x < float(s.n_depth - 1))) return false;
  d0 = int(x);
  fd = x - float(d0);
  return true;
}

// Every node's table value for a voxel of V-band depth tau_v at the table's
// angle coordinate u, from SpectralSceneView::node_table: bilinear in (tau_v,
// u) between its rows and bin centres, as TableView::lookup_at is in (tau_sct,
// u); the rows are at most the table's own row spacing apart at every node's
// scattering depth (node_table_values's host side, spectral_renderer.cpp), so
// the two differ by the table's own interpolation error. Beyond the last row
// every node is at the table's end, as its own lookup clamps there.
struct alignas(16) NodeCell {
  float v[4];
};
NEBULA_HD void node_table_values(const SpectralSceneView& s, float tau_v, float u, float* out) {
  const int n_mu = s.table.n_mu;
  float x = tau_v * s.node_table_inv_step;
  x = x >= 0.0f ? fminf(x, float(s.node_table_rows - 1)) : 0.0f;  // NaN and negative: row 0
  int i = int(x);
  if (i > s.node_table_rows - 2) i = s.node_table_rows - 2;
  const float ft = x - float(i);
  float y = u < 0.0f ? 0.0f : fminf(u, float(n_mu - 1));
  int k = int(y);
  if (k > n_mu - 2) k = n_mu - 2 > 0 ? n_mu - 2 : 0;
  const float fu = n_mu > 1 ? y - float(k) : 0.0f;
  const int k1 = k + 1 < n_mu ? k + 1 : k;
  const NodeCell* cells = reinterpret_cast<const NodeCell*>(s.node_table);
  const NodeCell a = cells[size_t(i) * n_mu + k], b = cells[size_t(i) * n_mu + k1];
  const NodeCell c = cells[size_t(i + 1) * n_mu + k], d = cells[size_t(i + 1) * n_mu + k1];
  NEBULA_UNROLL
  for (int m = 0; m < 4; ++m) {
    const float v0 = (1.0f - fu) * a.v[m] + fu * b.v[m];
    const float v1 = (1.0f - fu) * c.v[m] + fu * d.v[m];
    out[m] = (1.0f - ft) * v0 + ft * v1;
  }
}

// One voxel-star pair's weights on the powers of kappa - kappa_c: its light through
// filter f is sum_p b[p] integral S_f kappa (kappa - kappa_c)^p s e^(-kappa D) dlambda.
// The pair's light geometry is `light` = L/(4 pi) <1/r^2> c/l; its thin-limit
// weight w = light a tau_V p_HG(mu) (b[0] = w without a table); with one, P(tau_sct, u)
// times scale = light is the pair's weight at an attenuation (Double's exact lookups use
// it too).
struct PairWeights {
  float b[kMaxTableNodes];
  int n;
  float scale, tau_sct, u;  // tables: light (= w / (a tau_V p_HG)), a tau_V, the table's angle coordinate
  float tau_v, mu;          // varying albedo and g: the double integral's thin limit per wavelength
  float a0, a1;             // mean: P is averaged over the chord's angles a in [a0, a1] (chord_phase_mean)
  bool mean;
};
// at: the pair's chord (its angles near a star), or null for a point (the
// voxel-light pre-pass' centre): a chord seeing the star over enough of a
// uniform-theta table's bins takes the table's mean over them, as the band
// marcher does (tables/chord_phase.h); the thin limit keeps the midpoint.
// No division here: the march runs this per voxel and star.
NEBULA_HD PairWeights pair_weights_of_light(const SpectralSceneView& s, float light, float tau_v, float mu,
                                            const ChordIrradiance* at = nullptr) {
  PairWeights p;
  p.tau_sct = s.albedo * tau_v;
  p.b[0] = 0.0f;
  p.n = 1;
  p.scale = 0.0f;
  p.u = 0.0f;
  p.tau_v = tau_v;
  p.mu = mu;
  p.a0 = p.a1 = 0.0f;
  p.mean = false;
  if (s.n_nodes == 0) {  // the thin limit: p_HG (with a table its nodes' values replace it)
    p.b[0] = light * p.tau_sct * hg_phase(s.g, mu);
    return p;
  }
  if (!(p.tau_sct > 0.0f)) light = 0.0f;  // no scattering: every weight 0
  p.scale = light;
  p.u = s.table.angle_coordinate(mu);
  if (at && s.table.n_mu > 0 && s.table.C && chord_takes_phase_mean(s.table, at->a0, at->a1)) {
    p.mean = true;
    p.a0 = at->a0;
    p.a1 = at->a1;
  }
  float node[kMaxTableNodes];  // each node's P
  const bool one_read = s.node_table && !p.mean;  // every node's value in one read (node_table)
  if (one_read) node_table_values(s, tau_v, p.u, node);
  NEBULA_UNROLL
  for (int m = 0; m < kMaxTableNodes; ++m) {
    if (m >= s.n_nodes || one_read) break;
    TableView t = s.table;
    float tau_sct = p.tau_sct * s.node_kappa[m];
    if (s.varying) {  // the node's own albedo, g and table (or the thin limit)
      tau_sct = s.node_albedo[m] * tau_v * s.node_kappa[m];
      t.P = s.node_P[m];
      t.C = s.node_C[m];
    }
    node[m] = !t.P   ? tau_sct * hg_phase(s.node_g[m], mu)
              : p.mean ? chord_phase_mean(t, tau_sct, p.a0, p.a1, nullptr)
                       : t.lookup_at(tau_sct, p.u);
  }
  NEBULA_UNROLL
  for (int q = 0; q < kMaxTableNodes; ++q) {
    if (q >= s.n_nodes) break;
    float sum = 0.0f;
    NEBULA_UNROLL
    for (int m = 0; m < kMaxTableNodes; ++m)
      if (m < s.n_nodes) sum += s.node_weight[q * kMaxTableNodes + m] * node[m];
    p.b[q] = light * sum;
  }
  p.n = s.n_nodes;
  return p;
}
// The same from the pair's thin-limit weight w (the voxel-light pre-pass, which
// makes w with the phase folded in): b[0] = w without a table.
NEBULA_HD PairWeights pair_weights(const SpectralSceneView& s, float w, float tau_v, float mu,
                                   const ChordIrradiance* at = nullptr) {
  const float thin = s.albedo * tau_v * hg_phase(s.g, mu);
  if (s.n_nodes == 0 || !(thin > 0.0f)) {
    PairWeights p = pair_weights_of_light(s, 0.0f, tau_v, mu, at);
    p.b[0] = s.n_nodes == 0 ? w : 0.0f;
    return p;
  }
  return pair_weights_of_light(s, w / thin, tau_v, mu, at);
}

// D_d's bound (diffuse_voxel_terms): a noisy node ratio must not make the
// weights e^(kappa D_d) huge (their sum with e^(-kappa D) is the light; the
// basis methods drop pairs beyond their table's depth). Light reddened by more
// than tau_V 4 keeps the rest of its slope in the polynomial.
constexpr float kMaxDiffuseDepth = 4.0f;

// Light between voxels: one star's terms in a voxel (SpectralSceneView::diffuse)
// from what the band renderer's per-view pass gives at the nodes' attenuations
// kappa_m for a field baked from that star alone with spectral power power[m] =
// L s(lambda_m) (L_sun um^-1): H[m], the light the voxel scatters towards the
// eye per unit of chord / l. The voxel's light at wavelength lambda is
// L s(lambda) kappa u(kappa), u(kappa_m) = H[m] / (power[m] kappa_m) (the
// transport depends on lambda only through kappa: albedo and g are the same at
// every wavelength), and u is fitted as e^(-kappa D_d) sum_p B_p (kappa - kappa_c)^p:
// D_d from the outer nodes' ratio (light that reached the voxel through dust is
// redder: u falls with kappa), bounded by kMaxDiffuseDepth, then the polynomial
// through u_m e^(kappa_m D_d). Exact at the nodes, and between them for an
// exponential times a constant (or a polynomial of degree n_nodes - 1 that does
// not fall). out: B_0 .. B_(n-1), D_d.
NEBULA_HD void diffuse_voxel_terms(const SpectralSceneView& s, const float* H, const float* power, float* out) {
  const int n = s.n_nodes;
  float u[kMaxTableNodes], w[kMaxTableNodes];
  for (int m = 0; m < n; ++m) u[m] = power[m] > 0.0f ? fmaxf(H[m], 0.0f) / (power[m] * s.node_kappa[m]) : 0.0f;
  float D = 0.0f;
  if (n >= 2 && u[0] > 0.0f && u[n - 1] > 0.0f)
    D = fminf(fmaxf(0.0f, logf(u[0] / u[n - 1]) / (s.node_kappa[n - 1] - s.node_kappa[0])), kMaxDiffuseDepth);
  for (int m = 0; m < n; ++m) w[m] = u[m] * expf(s.node_kappa[m] * D);
  for (int p = 0; p < n; ++p) {
    float b = 0.0f;
    for (int m = 0; m < n; ++m) b += s.node_to_power[p * kMaxTableNodes + m] * w[m];
    out[p] = b;
  }
  out[n] = D;
}

// The voxel's V-band depth as the eye sees through it with the field's forward
// peak peak[m] at the nodes (the same for every star: the response of the
// voxel's table, p_(N+1)(a tau kappa_m)). The band marcher's transmittance is
// e^(-tau kappa c/l) + peak c/l; here it is matched at the V band over a whole
// voxel, tau_eye = -ln(e^(-tau_V) + pi(1)) with pi(kappa) / kappa interpolated
// between the nodes, and e^(-kappa tau_eye c/l) scales with kappa as the thin
// voxel's peak a tau kappa g^(N+1) does (docs/spectral.md).
NEBULA_HD float diffuse_eye_depth(const SpectralSceneView& s, const float* peak, float tau_v) {
  if (!(tau_v > 0.0f)) return 0.0f;
  float pi = 0.0f, xp = 1.0f;  // the polynomial through peak_m / kappa_m, at kappa = 1
  for (int p = 0; p < s.n_nodes; ++p, xp *= 1.0f - s.kappa_center)
    for (int m = 0; m < s.n_nodes; ++m) pi += s.node_to_power[p * kMaxTableNodes + m] * peak[m] / s.node_kappa[m] * xp;
  pi = fmaxf(pi, 0.0f);
  const float tau_eye = tau_v < 20.0f ? tau_v - log1pf(pi * expf(tau_v)) : -logf(pi + expf(-tau_v));
  return fminf(fmaxf(tau_eye, 0.0f), tau_v);
}

// Calls f(i) for i = 0 .. n - 1. kBound > 0 is a compile-time bound on n: the
// loop unrolls and i is a constant in each copy (the point of RayAccumulators).
template <int kBound, class F>
NEBULA_HD void for_each_index(int n, F&& f) {
  if constexpr (kBound > 0) {
    NEBULA_UNROLL
    for (int i = 0; i < kBound; ++i)
      if (i < n) f(i);
  } else {
    for (int i = 0; i < n; ++i) f(i);
  }
}

// Algorithm 1 over the shared breaks (SpectralSceneView::breaks): per filter f,
// sum_t weight[t] integral P_f(lambda) lambda^(offset[t] - 2) e^(-a/lambda) dlambda,
// P_f the piecewise cubic whose jumps are jumps[f][break][k], passed to emit(f, value).
// The antiderivatives at each break (expint.h, AntiderivativeWalk: each break's
// from the previous one's) are made once for all filters and terms; the
// convention (series or exact) is chosen once for the sum, by a / b at its
// smallest break.
template <int kBound, class Emit>
NEBULA_HD void closed_form(const SpectralSceneView& s, const double* jumps, int n_filters, double a, int n_terms,
                           const double* weight, const int* offset, Emit&& emit) {
  int lo = offset[0], hi = offset[0];
  for (int t = 1; t < n_terms; ++t) {
    lo = offset[t] < lo ? offset[t] : lo;
    hi = offset[t] > hi ? offset[t] : hi;
  }
  const int m_lo = lo, m_hi = hi + kAnalyticTerms - 1;
  constexpr int kSums = kBound > 0 ? kBound : kMaxAccumulators;
  double sum[kSums];
  for_each_index<kBound>(n_filters, [&](int f) { sum[f] = 0.0; });
  if (s.break_hi < s.break_lo) return;
  AntiderivativeWalk walk(a, !(a / s.breaks[s.break_lo] > 1.0), m_lo, m_hi);
  for (int j = s.break_lo; j <= s.break_hi; ++j) {
    double F[kMaxAntiderivatives];
    walk.at(s.breaks[j], F);
    for_each_index<kBound>(n_filters, [&](int f) {
      if (j < s.break_range[2 * f] || j > s.break_range[2 * f + 1]) return;
      const double* J = jumps + (size_t(f) * s.n_breaks + j) * kAnalyticTerms;
      double v = 0.0;
      for (int t = 0; t < n_terms; ++t) {
        const double* G = F + (offset[t] - m_lo);
        v += weight[t] * (J[0] * G[0] + J[1] * G[1] + J[2] * G[2] + J[3] * G[3]);
      }
      sum[f] += v;
    });
  }
  for_each_index<kBound>(n_filters, [&](int f) { emit(f, sum[f]); });
}

// A ray's accumulators acc(row, col), stored at image plane row * cols + col:
// the row is the star (Projection) or 0, the column the basis element
// (Projection, LightBasis) or the filter (Double, Analytic, VoxelLight);
// kBasis bounds the basis size where it is not the column (VoxelLight).
// Positive bounds make every loop over them unroll, so every index is a
// constant and the GPU keeps the accumulators in registers: an array indexed
// at run time lives in local memory, a read-modify-write through the caches
// per accumulator and voxel. 0: run-time extents within kMaxAccumulators (the
// CPU's choice, and the GPU's beyond its buckets, spectral_renderer_cuda.cu).
template <int kRowBound, int kColBound, int kBasisBound>
struct RayAccumulators {
  static constexpr int kRows = kRowBound, kCols = kColBound, kBasis = kBasisBound;
  static constexpr bool kFixed = kRows > 0 && kCols > 0;
  float v[kFixed ? kRows * kCols : kMaxAccumulators];
  int cols = 0;  // the run-time columns
  NEBULA_HD float& operator()(int row, int col) { return v[row * (kFixed ? kCols : cols) + col]; }
};
using DynamicAccumulators = RayAccumulators<0, 0, 0>;

// The accumulators' run-time rows and columns for a method (their product is n_acc).
NEBULA_HD int accumulator_rows(const SpectralSceneView& s) {
  return s.method == SpectralMethod::Projection ? s.n_stars : 1;
}
NEBULA_HD int accumulator_cols(const SpectralSceneView& s) {
  return s.method == SpectralMethod::Projection || s.method == SpectralMethod::LightBasis ? s.n_basis : s.n_acc;
}

// acc(row, col) into out[(row * cols + col) * stride] (an image's planes).
template <class Acc>
NEBULA_HD void store_accumulators(const SpectralSceneView& s, Acc& acc, float* out, size_t stride) {
  const int cols = accumulator_cols(s);
  for_each_index<Acc::kRows>(accumulator_rows(s), [&](int r) {
    for_each_index<Acc::kCols>(cols, [&](int c) { out[size_t(r * cols + c) * stride] = acc(r, c); });
  });
}

// Emission: the voxel's components seen through V-band depth D from the eye,
// weighted by `fraction` of a voxel edge crossed, into the emission planes em.
template <SpectralMethod kMethod>
NEBULA_HD void add_emission(const SpectralSceneView& s, size_t cell, float tau_v, float fraction, float D, float* em) {
  for (int c = 0; c < s.n_emission; ++c) {
    const SpectralEmissionView& e = s.emission[c];
    const float w = fraction * e.scale * (e.weight ? e.weight[cell] : tau_v);
    if (!(w > 0.0f)) continue;
    float* out = em + e.plane;
    if (e.line) {
      out[0] += w * expf(-e.line_kappa * D);
      continue;
    }
    if constexpr (kMethod == SpectralMethod::Double) {
      const float* q = s.emission_q + size_t(c) * s.n_acc * s.n_lambda;
      for (int i = 0; i < s.n_lambda; ++i) {
        const float t = w * expf(-s.kappa[i] * D);
        for (int f = 0; f < s.n_acc; ++f) out[f] += q[f * s.n_lambda + i] * t;
      }
    } else if constexpr (kMethod == SpectralMethod::Analytic) {
      // integral S_f phi e^(-C_T D / lambda), S_f phi piecewise cubic: powers k = 0..3 (m = k + 2).
      const double weight[1] = {1.0};
      const int offset[1] = {2};
      closed_form<0>(s, s.emission_jumps + size_t(c) * s.n_acc * s.n_breaks * kAnalyticTerms, s.n_acc,
                     s.C_T * double(D), 1, weight, offset, [&](int f, double v) { out[f] += w * float(v); });
    } else {
      int d0;
      float fd;
      if (!depth_row(s, D, d0, fd)) continue;
      // Preintegrated: the component's own table, one number per filter; else c_j(D), one per element.
      const int N = kMethod == SpectralMethod::Preintegrated ? s.n_acc : s.n_basis;
      const float* c0 = s.emission_coeff +
                        (kMethod == SpectralMethod::Preintegrated ? size_t(c) * s.n_depth * N : size_t(0)) +
                        size_t(d0) * N;
      for (int j = 0; j < N; ++j) out[j] += w * (c0[j] + fd * (c0[N + j] - c0[j]));
    }
  }
}

// The emission planes into out[(n_acc + k) * stride] (after the star planes).
NEBULA_HD void store_emission(const SpectralSceneView& s, const float* em, float* out, size_t stride) {
  for (int k = 0; k < s.n_emission_planes; ++k) out[size_t(s.n_acc + k) * stride] = em[k];
}

// Adds the pair's light in every accumulator (the method a template argument,
// so each kernel holds only its own code).
template <SpectralMethod kMethod, class Acc>
NEBULA_HD void add_pair(const SpectralSceneView& s, int star, const PairWeights& w, float D, Acc& acc) {
  switch (kMethod) {
    case SpectralMethod::Double: {
      const float* q = s.q + size_t(star) * s.n_acc * s.n_lambda;
      if (s.n_nodes == 0) {  // two loops, not a test per wavelength: the reference's time stays its own
        for (int i = 0; i < s.n_lambda; ++i) {
          const float e = w.b[0] * expf(-s.kappa[i] * D);
          for_each_index<Acc::kCols>(s.n_acc, [&](int f) { acc(0, f) += q[f * s.n_lambda + i] * e; });
        }
      } else if (s.varying) {
        for (int i = 0; i < s.n_lambda; ++i) {
          // The thin limit at this wavelength's own albedo and g: P / kappa = a tau p_HG.
          const float e =
              w.scale * s.lambda_albedo[i] * w.tau_v * hg_phase(s.lambda_g[i], w.mu) * expf(-s.kappa[i] * D);
          for_each_index<Acc::kCols>(s.n_acc, [&](int f) { acc(0, f) += q[f * s.n_lambda + i] * e; });
        }
      } else {
        for (int i = 0; i < s.n_lambda; ++i) {
          // P at this wavelength's own scattering depth (q holds S kappa s dlambda), over the chord's angles near a star.
          const float tau_sct = w.tau_sct * s.kappa[i];
          const float P = w.mean ? chord_phase_mean(s.table, tau_sct, w.a0, w.a1, nullptr) : s.table.lookup_at(tau_sct, w.u);
          const float e = w.scale * P / s.kappa[i] * expf(-s.kappa[i] * D);
          for_each_index<Acc::kCols>(s.n_acc, [&](int f) { acc(0, f) += q[f * s.n_lambda + i] * e; });
        }
      }
      break;
    }
    case SpectralMethod::Analytic: {
      // integral P_poly(lambda) kappa^(p+1) e^(-kappa D), kappa = C_T / lambda: C_T^(p+1) sum_k c_k I_(k-1-p),
      // with the weights on the powers of kappa - kappa_c expanded on those of kappa (exact here:
      // no table to fit, the closed form takes any power).
      double mono[kMaxTableNodes] = {};
      for (int p = 0; p < w.n; ++p) {
        double binomial = 1.0, shift = 1.0;  // C(p, q) (-kappa_c)^(p - q), q from p down
        for (int q = p; q >= 0; --q) {
          mono[q] += double(w.b[p]) * binomial * shift;
          binomial = binomial * q / double(p - q + 1);
          shift *= -double(s.kappa_center);
        }
      }
      // The power p of kappa = C_T / lambda times P's lambda^k: lambda^(k-1-p), m = k + 1 - p.
      double weight[kMaxTableNodes] = {};
      int offset[kMaxTableNodes] = {};
      double C_T_power = s.C_T;
      for (int p = 0; p < w.n; ++p, C_T_power *= s.C_T) {
        weight[p] = mono[p] * C_T_power;
        offset[p] = 1 - p;
      }
      closed_form<Acc::kCols>(s, s.jumps + size_t(star) * s.n_acc * s.n_breaks * kAnalyticTerms, s.n_acc,
                              s.C_T * double(D), w.n, weight, offset, [&](int f, double v) { acc(0, f) += float(v); });
      break;
    }
    case SpectralMethod::VoxelLight:
      break;  // summed per voxel ahead of the march (voxel_light)
    case SpectralMethod::Preintegrated: {
      int d0;
      float fd;
      if (!depth_row(s, D, d0, fd)) break;
      const int F = s.n_acc;
      for_each_index<kMaxTableNodes>(w.n, [&](int p) {
        const float* q = s.star_coeff + ((size_t(star) * s.n_powers + p) * s.n_depth + d0) * F;
        const float wp = w.b[p];
        for_each_index<Acc::kCols>(F, [&](int f) { acc(0, f) += wp * (q[f] + fd * (q[F + f] - q[f])); });
      });
      break;
    }
    case SpectralMethod::Projection:
    case SpectralMethod::LightBasis: {
      int d0;
      float fd;
      if (!depth_row(s, D, d0, fd)) break;
      const int N = s.n_basis;
      // One block of coefficient tables per power of kappa; without a table the
      // first alone (its own branch, so that the thin limit's code is what it was).
      const auto add_block = [&](int p, float wp) {
        if constexpr (kMethod == SpectralMethod::Projection) {
          const float* c0 = s.coeff + (size_t(p) * s.n_depth + d0) * N;
          if constexpr (Acc::kCols == 4) {
            if (N == 4) {  // rows of 4 start on 16 bytes (the table's base is aligned): two vector reads
              const NodeCell lo = reinterpret_cast<const NodeCell*>(c0)[0], hi = reinterpret_cast<const NodeCell*>(c0)[1];
              NEBULA_UNROLL
              for (int j = 0; j < 4; ++j) acc(star, j) += wp * (lo.v[j] + fd * (hi.v[j] - lo.v[j]));
              return;
            }
          }
          for_each_index<Acc::kCols>(N, [&](int j) { acc(star, j) += wp * (c0[j] + fd * (c0[N + j] - c0[j])); });
        } else {
          const float u = s.stars[star].temperature_u;
          const int t_last = s.n_temperature > 1 ? s.n_temperature - 2 : 0;
          const int t0 = int(u) < t_last ? int(u) : t_last;
          const float ft = s.n_temperature > 1 ? u - float(t0) : 0.0f;
          const float* c00 = s.coeff + ((size_t(p) * s.n_temperature + t0) * s.n_depth + d0) * N;
          const float* c10 = s.n_temperature > 1 ? c00 + size_t(s.n_depth) * N : c00;
          for_each_index<Acc::kCols>(N, [&](int j) {
            const float lo = c00[j] + fd * (c00[N + j] - c00[j]);
            const float hi = c10[j] + fd * (c10[N + j] - c10[j]);
            acc(0, j) += wp * (lo + ft * (hi - lo));
          });
        }
      };
      if (s.n_nodes == 0)
        add_block(0, w.b[0]);
      else  // unrolled, so that b[p] is a register on the GPU
        for_each_index<kMaxTableNodes>(w.n, [&](int p) { add_block(p, w.b[p]); });
      break;
    }
  }
}

// Light between voxels: star k's terms in the voxel (diffuse_voxel_terms)
// added as a pair of the star's at V-band depth eye_depth + D_d, with weights
// L_k fraction B_p (VoxelLight adds them in its pre-pass).
template <SpectralMethod kMethod, class Acc>
NEBULA_HD void add_diffuse(const SpectralSceneView& s, int k, size_t cell, float fraction, float eye_depth, Acc& acc) {
  const int n = s.n_nodes;
  const float* t = s.diffuse + (cell * s.n_stars + k) * size_t(n + 1);
  PairWeights w;
  w.n = n;
  w.scale = w.tau_sct = w.u = w.tau_v = w.mu = w.a0 = w.a1 = 0.0f;
  w.mean = false;
  const float scale = s.stars[k].power * fraction;
  NEBULA_UNROLL
  for (int p = 0; p < kMaxTableNodes; ++p) w.b[p] = p < n ? scale * t[p] : 0.0f;
  const float D = eye_depth + t[n];
  if constexpr (kMethod == SpectralMethod::Double) {
    // sum_p B_p (kappa - kappa_c)^p at each wavelength (q holds S kappa s dlambda).
    const float* q = s.q + size_t(k) * s.n_acc * s.n_lambda;
    for (int i = 0; i < s.n_lambda; ++i) {
      const float x = s.kappa[i] - s.kappa_center;
      float poly = 0.0f, xp = 1.0f;
      for (int p = 0; p < n; ++p, xp *= x) poly += w.b[p] * xp;
      const float e = poly * expf(-s.kappa[i] * D);
      for_each_index<Acc::kCols>(s.n_acc, [&](int f) { acc(0, f) += q[f * s.n_lambda + i] * e; });
    }
  } else {
    add_pair<kMethod>(s, k, w, D, acc);
  }
}

// VoxelLight: the coefficients of the table at depth D (false beyond it);
// kWidth > 0 bounds width at compile time (RayAccumulators).
template <int kWidth = 0>
NEBULA_HD bool depth_coefficients(const SpectralSceneView& s, const float* table, int width, float D, float* out) {
  int d0;
  float fd;
  if (!depth_row(s, D, d0, fd)) return false;
  const float* c0 = table + size_t(d0) * width;
  for_each_index<kWidth>(width, [&](int i) { out[i] = c0[i] + fd * (c0[width + i] - c0[i]); });
  return true;
}

// VoxelLight: star k's row of Q_fj (kappa's power p block) at its depth to
// `cell`, interpolated as row[i] + fd (row[F N + i] - row[i]); null beyond the table.
NEBULA_HD size_t star_row(const SpectralSceneView& s, int k, int p, int d0) {
  return ((size_t(k) * s.n_powers + p) * s.n_depth + d0) * (s.n_acc * s.n_basis);
}
NEBULA_HD const float* star_integrals(const SpectralSceneView& s, int k, int p, size_t cell, float& fd) {
  int d0;
  if (!depth_row(s, s.stars[k].depth_v[cell], d0, fd)) return nullptr;
  return s.star_coeff + star_row(s, k, p, d0);
}

// u[c * stride + i] += (w, grad)[c] times the star's row q interpolated at fd,
// for c = 0 .. 3 and i < FN. kFN > 0 bounds FN at compile time for the GPU's
// register sums (stride kFN; the loop unrolls, so every index is a constant);
// with kFN = 0 it is the CPU's plain loop, which vectorises.
template <int kFN = 0>
NEBULA_HD void add_star_light(float* __restrict__ u, int stride, const float* __restrict__ q, int FN, float fd,
                              float w, Vec3 grad, int i0 = 0) {
  NEBULA_UNROLL
  for (int j = 0; j < (kFN > 0 ? kFN : FN); ++j) {
    const int i = i0 + j;
    if (kFN > 0 && i >= FN) break;
    const float v = q[i] + fd * (q[FN + i] - q[i]);
    u[j] += w * v;
    u[stride + j] += grad.x * v;
    u[2 * stride + j] += grad.y * v;
    u[3 * stride + j] += grad.z * v;
  }
}

// VoxelLight: one voxel-star pair of the pre-pass, for a voxel at `centre`
// (e its direction to the eye, inv_rho 1 / its distance from the eye or 0,
// tau its V-band depth) and a star at `star` (power: its luminosity times
// a (1 - g^2) / (4 pi)^2, VoxelLightConstants::power) at V-band depth `depth`
// from the voxel: the weight w = a tau_V L/(4 pi r^2) p_HG(mu) (0 where the
// pair is not summed: an empty voxel, a near pair, beyond the table), its
// gradient, the star table's depth coordinate x and near = 1 where the march
// takes the pair exactly. Branch-free: arithmetic and 0/1 masks, so that the
// CPU's rows of voxels vectorise.
struct VoxelStarPair {
  float w, gx, gy, gz, x, near, mu;
};
// What every pair of one pre-pass shares, and star k's part (taken out of the
// loop over the voxels by hand: the CPU's loop vectorises only so).
struct VoxelLightConstants {
  float near2, g2, phase_norm, inv_step, last;
  NEBULA_HD explicit VoxelLightConstants(const SpectralSceneView& s)
      : near2(0.5f * s.near_distance * s.near_distance), g2(s.g * s.g),
        phase_norm((1.0f - s.g * s.g) * kInv4Pi * s.albedo), inv_step(1.0f / s.depth_step),
        last(float(s.n_depth - 1)) {}
  NEBULA_HD float power(const SpectralSceneView& s, int k) const {
    return s.stars[k].power * kInv4Pi * phase_norm;
  }
};
NEBULA_HD VoxelStarPair voxel_star_pair(const SpectralSceneView& s, const Camera& camera,
                                        const VoxelLightConstants& c, Vec3 star, float power, Vec3 centre, Vec3 e,
                                        float inv_rho, float tau, float depth) {
  const float near2 = c.near2, g2 = c.g2;
  const float dx = centre.x - star.x, dy = centre.y - star.y, dz = centre.z - star.z;
  const float r2 = dx * dx + dy * dy + dz * dz;
  const float inv_r = 1.0f / sqrtf(r2 + 1e-30f);
  const float hx = dx * inv_r, hy = dy * inv_r, hz = dz * inv_r;
  const float mu = hx * e.x + hy * e.y + hz * e.z;
  // The expansion's error is second order, (offset / r)^2 times the curvature of ln w
  // in the angle seen from the star: 2 for 1/r^2, plus the phase's |d^2 ln p / d theta^2|
  // (3g / (1 - g)^2 in forward scattering: 11 at g = 0.6). near_distance holds for
  // the curvature 2 of 1/r^2 alone; a sharper phase widens it as the square root.
  const float A = 1.0f + g2 - 2.0f * s.g * mu, inv_A = 1.0f / A;
  const float curvature = 2.0f + fabsf(3.0f * s.g * (mu * A - 2.0f * s.g * (1.0f - mu * mu))) * inv_A * inv_A;
  const float lit = tau > 0.0f ? 1.0f : 0.0f;
  // The pixel's width at the star: within 6 of them a ray's chords take the
  // square pixel's mean of 1/b (illumination/chord_irradiance.h), which a
  // voxel's light cannot (it has no ray), to within 1%; those pairs are exact too.
  const float t_star =
      (camera.position.x - star.x) * e.x + (camera.position.y - star.y) * e.y + (camera.position.z - star.z) * e.z;
  const float width = s.footprint.width_at_eye + 0.5f * (t_star + fabsf(t_star)) * s.footprint.spread;
  const float w2 = width * width;
  const float close = r2 < near2 * curvature || r2 < 36.0f * w2 ? lit : 0.0f;
  const float x = depth * c.inv_step;
  // Products of 0/1 flags, not &&: no branch (beyond the table: below the transmittance cut).
  const float take = (lit - close) * (x < c.last ? 1.0f : 0.0f);
  // r^2 as the rays' chords take it beyond 6 pixel widths (chord_irradiance's
  // far formula, pixel_mean_b2<false>): r^2 - w^2 / 12.
  const float inv_r2 = 1.0f / fmaxf(r2 - w2 * (1.0f / 12.0f), 1e-30f);
  const float wi = power * tau * inv_r2 * inv_A * sqrtf(inv_A) * take;
  // grad ln w = -2 d / r2 + (d ln p / d mu) grad mu, grad mu = (e - mu h) / r - (h - mu e) / rho.
  const float a = -2.0f * inv_r2, b = 3.0f * s.g * inv_A;
  VoxelStarPair out;
  out.gx = wi * (a * dx + b * (inv_r * (e.x - mu * hx) - inv_rho * (hx - mu * e.x)));
  out.gy = wi * (a * dy + b * (inv_r * (e.y - mu * hy) - inv_rho * (hy - mu * e.y)));
  out.gz = wi * (a * dz + b * (inv_r * (e.z - mu * hz) - inv_rho * (hz - mu * e.z)));
  out.w = wi;
  out.x = x * take;
  out.near = close;
  out.mu = mu;
  return out;
}

// Adds one pre-pass pair (weight w > 0, its gradient, star k at table
// position x) to the sums u. With a table, one row of Q per power of kappa,
// each weighted by its part b_p of the pair's weight: their sum V = sum_p b_p
// Q_p is formed first, then added as add_star_light adds w Q (the gradient
// scaled by V / w: the table's own change with the angle across the voxel is
// left out, slow beside p_HG's, whose change the gradient carries).
// kFN > 0: the sums of outputs i0 .. i0 + kFN - 1 only (a slice: the GPU's
// pre-pass gives each voxel several threads), u[j] standing for output i0 + j.
template <int kFN = 0>
NEBULA_HD void add_pair_light(const SpectralSceneView& s, float* __restrict__ u, int stride, int k, float tau_v,
                              float w, float gx, float gy, float gz, float x, float mu, int i0 = 0) {
  const int FN = s.n_acc * s.n_basis;
  const int d0 = int(x);
  const float fd = x - float(d0);
  if (s.n_nodes == 0) {
    add_star_light<kFN>(u, stride, s.star_coeff + star_row(s, k, 0, d0), FN, fd, w, Vec3{gx, gy, gz}, i0);
    return;
  }
  const PairWeights pw = pair_weights(s, w, tau_v, mu);
  const float inv_w = 1.0f / w;
  const float rx = gx * inv_w, ry = gy * inv_w, rz = gz * inv_w;
  const float* q0 = s.star_coeff + star_row(s, k, 0, d0);
  const size_t block = size_t(s.n_depth) * FN;  // from one power's rows to the next's
  NEBULA_UNROLL
  for (int j = 0; j < (kFN > 0 ? kFN : FN); ++j) {
    const int i = i0 + j;
    if (kFN > 0 && i >= FN) break;
    float v = 0.0f;
    for_each_index<kMaxTableNodes>(pw.n, [&](int p) {
      const float* q = q0 + size_t(p) * block;
      v += pw.b[p] * (q[i] + fd * (q[FN + i] - q[i]));
    });
    u[j] += v;
    u[stride + j] += rx * v;
    u[2 * stride + j] += ry * v;
    u[3 * stride + j] += rz * v;
  }
}

// VoxelLight: star k's light between voxels in the voxel into its centre's
// sums u[i] (i < F N; no gradient: the field's light is the voxel's own),
// L_k sum_p B_p Q^p(k, D_d); the march weighs it by c_j(D_eye) as the star's
// direct light.
template <int kFN = 0>
NEBULA_HD void add_diffuse_light(const SpectralSceneView& s, float* __restrict__ u, int k, size_t cell, int i0 = 0) {
  const int n = s.n_nodes, FN = s.n_acc * s.n_basis;
  const float* t = s.diffuse + (cell * s.n_stars + k) * size_t(n + 1);
  int d0;
  float fd;
  if (!depth_row(s, t[n], d0, fd)) return;
  const size_t block = size_t(s.n_depth) * FN;
  const float* q0 = s.star_coeff + star_row(s, k, 0, d0);
  const float power = s.stars[k].power;
  NEBULA_UNROLL
  for (int j = 0; j < (kFN > 0 ? kFN : FN); ++j) {
    const int i = i0 + j;
    if (kFN > 0 && i >= FN) break;
    float v = 0.0f;
    for_each_index<kMaxTableNodes>(n, [&](int p) {
      const float* q = q0 + size_t(p) * block;
      v += t[p] * (q[i] + fd * (q[FN + i] - q[i]));
    });
    u[j] += power * v;
  }
}

// VoxelLight's per-view pre-pass for voxels x0 .. x0 + kRow - 1 (those below
// the grid's edge) of row (y, z): U = a tau_V sum_k L_k/(4 pi r^2) p_HG(mu)
// Q(star k, D_k) at each voxel's centre and its gradient (analytic: 1/r^2 and
// mu, with the direction to the eye varying across the voxel as the rays
// through it do), into light[cell][4][F N]; near[cell] bit k: star k's pair
// taken exactly in the march instead. Cost: voxels x stars, once per view.
// The CPU runs rows of 16 voxels: first every star's pair per voxel side by
// side (vectorised), then the sums star by star. The GPU runs a voxel's
// outputs in slices of kFN (kRow 1), one thread each: star by star into the
// slice's 4 kFN sums held in registers, each output written once; slice 0
// writes the near mask (kFN 0: the CPU's order, its per-star arrays in local
// memory). Every slice repeats the pairs' geometry; it holds fewer sums.
template <int kRow, int kFN = 0>
NEBULA_HD void voxel_light(const SpectralSceneView& s, const Camera& camera, int x0, int y, int z, float* light,
                           unsigned* near, int slice = 0) {
  const GridShape& g = s.density.shape;
  const int n = g.nx - x0 < kRow ? g.nx - x0 : kRow;
  const size_t cell0 = g.index(x0, y, z);
  const int FN = s.n_acc * s.n_basis;
  const Vec3 c0 = g.centre(x0, y, z);
  const VoxelLightConstants constants(s);
  // The rays' direction turns by (offset / distance to the eye) across the voxel.
  auto inv_rho_of = [&](Vec3 centre) {
    const float rho = length(camera.position - centre);
    return camera.projection == Projection::Orthographic || !(rho > 0.0f) ? 0.0f : 1.0f / rho;
  };
  if constexpr (kRow == 1 && kFN > 0) {
    const Vec3 e = camera.to_eye(c0);
    const float inv_rho = inv_rho_of(c0), tau = s.density.tau_v[cell0];
    const int i0 = slice * kFN;
    float u[4 * kFN];
    for_each_index<4 * kFN>(4 * kFN, [&](int i) { u[i] = 0.0f; });
    unsigned mask = 0;
    for (int k = 0; k < s.n_stars; ++k) {
      const VoxelStarPair p = voxel_star_pair(s, camera, constants, s.stars[k].position, constants.power(s, k), c0, e,
                                              inv_rho, tau, s.stars[k].depth_v[cell0]);
      mask |= unsigned(p.near != 0.0f) << k;
      if (p.w == 0.0f) continue;
      add_pair_light<kFN>(s, u, kFN, k, tau, p.w, p.gx, p.gy, p.gz, p.x, p.mu, i0);
    }
    if (s.diffuse && tau > 0.0f)
      for (int k = 0; k < s.n_stars; ++k) add_diffuse_light<kFN>(s, u, k, cell0, i0);
    float* out = light + cell0 * 4 * FN + i0;
    for_each_index<kFN>(FN - i0 < kFN ? FN - i0 : kFN, [&](int j) {
      out[j] = u[j];
      out[FN + j] = u[kFN + j];
      out[2 * FN + j] = u[2 * kFN + j];
      out[3 * FN + j] = u[3 * kFN + j];
    });
    if (slice == 0) near[cell0] = mask;
  } else {
    // Per voxel: the way to the eye, 1 / distance to it, the depth; one array per
    // component (not Vec3s), so that the loop over the voxels below vectorises.
    float ex[kRow], ey[kRow], ez[kRow], inv_rho[kRow], tau[kRow];
    for (int i = 0; i < n; ++i) {
      const Vec3 centre{c0.x + float(i) * g.voxel, c0.y, c0.z};
      const Vec3 e = camera.to_eye(centre);
      ex[i] = e.x;
      ey[i] = e.y;
      ez[i] = e.z;
      inv_rho[i] = inv_rho_of(centre);
      tau[i] = s.density.tau_v[cell0 + i];
    }
    // Per star and voxel: weight, its gradient, the table position; the near mask.
    float w[kMaxVoxelLightStars][kRow], gx[kMaxVoxelLightStars][kRow], gy[kMaxVoxelLightStars][kRow],
        gz[kMaxVoxelLightStars][kRow], xd[kMaxVoxelLightStars][kRow], is_near[kMaxVoxelLightStars][kRow],
        mu[kMaxVoxelLightStars][kRow];
    for (int k = 0; k < s.n_stars; ++k) {
      const float* depth = s.stars[k].depth_v + cell0;
      const Vec3 star = s.stars[k].position;
      const float power = constants.power(s, k);
      for (int i = 0; i < n; ++i) {
        const Vec3 centre{c0.x + float(i) * g.voxel, c0.y, c0.z};
        const VoxelStarPair p =
            voxel_star_pair(s, camera, constants, star, power, centre, Vec3{ex[i], ey[i], ez[i]}, inv_rho[i], tau[i],
                            depth[i]);
        w[k][i] = p.w;
        gx[k][i] = p.gx;
        gy[k][i] = p.gy;
        gz[k][i] = p.gz;
        xd[k][i] = p.x;
        is_near[k][i] = p.near;
        mu[k][i] = p.mu;
      }
    }
    for (int i = 0; i < n; ++i) {
      float* u = light + (cell0 + i) * 4 * FN;
      for (int j = 0; j < 4 * FN; ++j) u[j] = 0.0f;
      for (int k = 0; k < s.n_stars; ++k) {
        if (w[k][i] == 0.0f) continue;
        add_pair_light(s, u, FN, k, tau[i], w[k][i], gx[k][i], gy[k][i], gz[k][i], xd[k][i], mu[k][i]);
      }
      if (s.diffuse && tau[i] > 0.0f)
        for (int k = 0; k < s.n_stars; ++k) add_diffuse_light(s, u, k, cell0 + i);
      unsigned mask = 0;
      for (int k = 0; k < s.n_stars; ++k) mask |= unsigned(is_near[k][i] != 0.0f) << k;
      near[cell0 + i] = mask;
    }
  }
}

// Whether a ray passes within s.near_star_radius of a star: only those take
// the phase's mean over their chords' angles (kChordPhase below).
NEBULA_HD bool passes_near_a_star(const SpectralSceneView& s, Vec3 origin, Vec3 dir) {
  return nebula::passes_near_a_star(s.stars, s.n_stars, s.near_star_radius, s.footprint, origin, dir);
}

// One ray: the accumulators (n_acc of them) before the resolve.
// em: the emission's planes (n_emission_planes of them; null without emission).
// kChordPhase: the pairs whose chords see a star over enough of the table's
// angle bins take the mean of P over them (pair_weights); only the rays that
// passes_near_a_star picks have such chords, so the others march without it
// and the kernel marching them keeps its registers (the image is the same).
template <SpectralMethod kMethod, bool kChordPhase = false, class Acc>
NEBULA_HD void march_spectral(const SpectralSceneView& s, Vec3 origin, Vec3 dir, Acc& acc, float* em = nullptr) {
  acc.cols = accumulator_cols(s);
  for_each_index<Acc::kRows>(accumulator_rows(s), [&](int r) {
    for_each_index<Acc::kCols>(acc.cols, [&](int c) { acc(r, c) = 0.0f; });
  });
  for (int k = 0; k < s.n_emission_planes; ++k) em[k] = 0.0f;
  const GridShape& g = s.density.shape;
  const Vec3 span = g.upper() - g.origin;
  const float far = length(origin - (g.origin + 0.5f * span)) + length(span) + g.voxel;
  float t_enter = 0.0f, t_exit = 0.0f;
  if (!clip_to_grid(g, origin, dir, far, t_enter, t_exit)) return;
  const float inv_voxel = 1.0f / g.voxel;
  const Vec3 to_eye = -dir;
  const NearStar image_star = near_star<kChordPhase>(s.stars, s.n_stars, origin, dir, s.footprint);
  float t = t_enter, eye_depth = 0.0f;  // V-band depth from the eye to the current voxel's entry
  traverse_segment_cells(g, origin, origin + far * dir, [&](int ix, int iy, int iz, size_t cell, float chord) -> bool {
    const float tau_v = s.density.tau_v[cell];
    const float fraction = chord * inv_voxel;
    if constexpr (kMethod == SpectralMethod::VoxelLight) {
      float c[Acc::kBasis > 0 ? Acc::kBasis : kMaxBasis];
      if (tau_v > 0.0f && depth_coefficients<Acc::kBasis>(s, s.coeff, s.n_basis, eye_depth, c)) {
        const int F = s.n_acc, N = s.n_basis, FN = F * N;
        const float* u = s.voxel_light + cell * 4 * FN;
        const Vec3 delta = origin + (t + 0.5f * chord) * dir - g.centre(ix, iy, iz);
        for_each_index<Acc::kCols>(F, [&](int f) {
          float sum = 0.0f;
          for_each_index<Acc::kBasis>(N, [&](int j) {
            const int i = f * N + j;
            sum += c[j] * (u[i] + delta.x * u[FN + i] + delta.y * u[2 * FN + i] + delta.z * u[3 * FN + i]);
          });
          acc(0, f) += fraction * sum;
        });
        for (unsigned near = s.near_stars[cell]; near != 0u; near &= near - 1u) {
          int k = 0;
          while (!((near >> k) & 1u)) ++k;
          float fd = 0.0f;
          if (!star_integrals(s, k, 0, cell, fd)) continue;
          const ChordIrradiance at = chord_irradiance<kChordPhase>(image_star, k, s.stars[k].position, origin, dir, t,
                                                                    t + chord, s.footprint);
          const Vec3 d = at.point - s.stars[k].position;
          const float r2 = dot(d, d);
          const float mu = r2 > 0.0f ? dot(d, to_eye) * reciprocal_sqrt(r2) : 0.0f;
          const PairWeights w = pair_weights_of_light(s, s.stars[k].power * kInv4Pi * at.inv_r2 * fraction, tau_v, mu,
                                                      kChordPhase ? &at : nullptr);
          for_each_index<kMaxTableNodes>(w.n, [&](int p) {
            const float* q = star_integrals(s, k, p, cell, fd);
            for_each_index<Acc::kCols>(F, [&](int f) {
              float sum = 0.0f;
              for_each_index<Acc::kBasis>(N, [&](int j) {
                const int i = f * N + j;
                sum += c[j] * (q[i] + fd * (q[FN + i] - q[i]));
              });
              acc(0, f) += w.b[p] * sum;
            });
          });
        }
      }
    } else if (tau_v > 0.0f) {
      // Projection's accumulators have a row per star: unrolled over the stars, so that row is a constant.
      for_each_index<kMethod == SpectralMethod::Projection ? Acc::kRows : 0>(s.n_stars, [&](int k) {
        const ChordIrradiance at = chord_irradiance<kChordPhase>(image_star, k, s.stars[k].position, origin, dir, t,
                                                                    t + chord, s.footprint);
        const Vec3 d = at.point - s.stars[k].position;
        const float r2 = dot(d, d);
        const float mu = r2 > 0.0f ? dot(d, to_eye) * reciprocal_sqrt(r2) : 0.0f;
        const float light = s.stars[k].power * kInv4Pi * at.inv_r2 * fraction;
        add_pair<kMethod>(s, k, pair_weights_of_light(s, light, tau_v, mu, kChordPhase ? &at : nullptr),
                          s.stars[k].depth_v[cell] + eye_depth, acc);
        if (s.diffuse) add_diffuse<kMethod>(s, k, cell, fraction, eye_depth, acc);
      });
    }
    if (s.n_emission > 0) add_emission<kMethod>(s, cell, tau_v, fraction, eye_depth, em);
    t += chord;
    // The eye sees through the voxel's dust less its diffuse field's forward peak (diffuse_eye_depth).
    eye_depth += (s.eye_tau ? s.eye_tau[cell] : tau_v) * fraction;
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
    case SpectralMethod::Preintegrated:
      f(std::integral_constant<SpectralMethod, SpectralMethod::Preintegrated>());
      break;
  }
}

}  // namespace nebula::spectral
