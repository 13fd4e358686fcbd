#pragma once
// The zonal response of a cell's field (docs/diffuse.md, "Zonal degrees"),
// written once for the grid marcher's per-view pass (raycast/diffuse_light.h)
// and the axial marcher's per-sample light (axial/axial_march.h): the
// harmonics' D_l up to the field's degree, above it each zonal star's sums
// about the direction from the star to `point`, blended with the harmonics'
// own response by the zonal weight.
#include "core/hd.h"
#include "core/vec3.h"
#include "diffuse/diffuse_field.h"

namespace nebula {

// Two floats at p (8-byte aligned): one 8-byte load on the device.
struct Pair {
  float v[2];
};
NEBULA_HD Pair load_pair(const float* p) {
#if NEBULA_ON_DEVICE
  const float2 q = *reinterpret_cast<const float2*>(p);
  return {{q.x, q.y}};
#else
  return {{p[0], p[1]}};
#endif
}

// Adds one zonal star's degrees deg + 1..f.zonal to both rows' sums of every
// band with a field (at[b] >= 0): w y_l(mu) Z_l r_l, with Y_l0 = sqrt((2l + 1)
// / (4 pi)) P_l(mu), mu the cosine between the eye and the direction from the
// star to the dust (r), z the star's zonal sums Z_l in the cell.
template <int kDeg>
NEBULA_HD void add_zonal_star(const DiffuseView& f, const float* z, Vec3 r, Vec3 to_eye, float w, int deg,
                              const int (&at)[kMaxBands], float (&s0)[kMaxBands], float (&s1)[kMaxBands]) {
  const float len = length(r);
  const float mu = len > 0.0f ? dot(to_eye, r) / len : to_eye.z;
  float p_prev = 1.0f, p_l = mu;  // P_0 and P_1, then P_{l-1} and P_l
  NEBULA_UNROLL
  for (int l = 1; l < kDeg; ++l) {
    if (l >= deg) break;
    const float next = ((2.0f * l + 1.0f) * mu * p_l - float(l) * p_prev) / float(l + 1);
    p_prev = p_l;
    p_l = next;
  }
  if (deg == 0) p_l = 1.0f, p_prev = 0.0f;  // P_0 and "P_-1" (its weight is 0 below)
  // Two degrees at a time: one 8-byte load per row and band serves both
  // (rows of neighbouring voxels differ, so each scalar load is a gather);
  // unrolled, so that every degree's constants are known at compile time.
  NEBULA_UNROLL
  for (int pair = 0; pair < kMaxZonalDegree / 2 + 1; ++pair) {
    if (2 * pair + 1 <= deg) continue;  // both degrees within the harmonics
    if (2 * pair > f.zonal) break;
    Quad d[2];  // w y_l Z_l per band, l = 2 pair + j (0 outside deg < l <= zonal)
    NEBULA_UNROLL
    for (int j = 0; j < 2; ++j) {
      const int l = 2 * pair + j;
      d[j] = Quad{{0.0f, 0.0f, 0.0f, 0.0f}};
      if (l <= deg || l > f.zonal) continue;
      const float next = ((2.0f * l - 1.0f) / float(l)) * mu * p_l - (float(l - 1) / float(l)) * p_prev;
      p_prev = p_l;
      p_l = next;
      const float y = w * (sqrtf((2.0f * l + 1.0f) * 0.07957747154594767f) * next);
      d[j] = load_quad(z + size_t(l - deg - 1) * 4);
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b) d[j].v[b] *= y;
    }
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b)
      if (at[b] >= 0) {
        const float* row = f.response[b] + at[b];
        const Pair r0 = load_pair(row + 2 * pair), r1 = load_pair(row + f.stride + 2 * pair);
        NEBULA_UNROLL
        for (int j = 0; j < 2; ++j) {
          s0[b] += r0.v[j] * d[j].v[b];
          s1[b] += r1.v[j] * d[j].v[b];
        }
      }
  }
}

// The light the dust at `point` (of V-band depth tau_v, so of scattering depth
// s.albedo[b] tau_v s.extinction_ratio[b] per band of the marcher's scene s,
// in field cell `cell`) sends towards the eye (unit to_eye) with the zonal
// response, and its forward peak, per band with a field; false, with nothing
// written, where the zonal weight is 0 (then the harmonics' own response,
// DiffuseView::scattered, is the whole answer). D holds the harmonics'
// projections on the way to the eye in the field's frame (DiffuseView::project;
// for axial maps the meridian's), for l <= deg; deg and kDeg as for project:
// kDeg bounds deg at compile time, the grid passes its degree as both.
//
// The response is linear in the D_l, so the stars are taken one after the
// other (add_zonal_star). Each band's two table rows around tau_sct are
// summed apart and interpolated once at the end, and the blend with the
// harmonics' own response, (1 - w) own + w zonal, is folded into the sums
// (they start at (1 - w) own, every zonal term carries w): only the sums, the
// rows and where tau_sct lies between them stay alive through the stars.
template <int kDeg, class Scene>
NEBULA_HD bool zonal_scattered_light(const Scene& s, const DiffuseView& f, float tau_v, size_t cell,
                                     Vec3 point, Vec3 to_eye, const float (&D)[kMaxBands][kDeg + 1],
                                     float (&light)[kMaxBands], float (&peak)[kMaxBands], int deg = kDeg,
                                     bool clamp = true) {
  const float w = f.zonal_weight(point, to_eye);
  if (!(w > 0.0f)) return false;
  float s0[kMaxBands] = {}, s1[kMaxBands] = {};
  int at[kMaxBands];  // the lower row's offset in f.response[b]; -1: the band has no field
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b) {
    at[b] = -1;
    if (!(b < s.n_bands && f.has[b])) continue;
    const float tau_sct = s.albedo[b] * tau_v * s.extinction_ratio[b];
    float frac = 0.0f;
    const float* row = f.response_row(b, tau_sct, &frac);
    at[b] = int(row - f.response[b]);
    float h0 = 0.0f, h1 = 0.0f;  // the harmonics' degrees under the zonal response
    NEBULA_UNROLL
    for (int l = 0; l <= kDeg; ++l) {
      if (l > deg) break;
      h0 += row[l] * D[b][l];
      h1 += row[f.stride + l] * D[b][l];
    }
    float own_peak = 0.0f;
    const float own = (1.0f - w) * f.scattered<kDeg>(b, tau_sct, D[b], &own_peak, deg);
    s0[b] = own + w * h0;
    s1[b] = own + w * h1;
  }
  const size_t n_zonal = size_t(f.zonal - deg);
  const float* block = f.packed + (cell * size_t(f.coeffs) + size_t(sh_count(deg))) * 4;
  // Unrolled to the most zonal stars, leaving at the scene's count: a run-time
  // loop around the inlined body spilled 156 bytes at the grid pass' 64
  // registers, this code 20 there and 8 at its launch's 72 (ptxas, sm_90).
  NEBULA_UNROLL
  for (int k = 0; k < kMaxZonalStars; ++k) {
    if (k >= f.zonal_stars) break;
    add_zonal_star<kDeg>(f, block + size_t(k) * n_zonal * 4, point - f.zonal_star[k], to_eye, w, deg, at, s0, s1);
  }
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (at[b] >= 0) {
      // Where tau_sct lies between the rows, found again rather than kept through the stars.
      const float tau_sct = s.albedo[b] * tau_v * s.extinction_ratio[b];
      float frac = 0.0f;
      f.response_row(b, tau_sct, &frac);
      light[b] = s0[b] + frac * (s1[b] - s0[b]);
      if (clamp) light[b] = fmaxf(0.0f, light[b]);
      peak[b] = f.peak(b, tau_sct, w);
    }
  return true;
}

// The light field cell `cell` sends towards the eye (unit to_eye) from the dust
// at `point` (V-band depth tau_v) per band with a field, and its forward peak:
// the harmonics' response, or with zonal degrees (kZonal) the zonal one where
// its weight is above 0. clamp: never negative (a voxel's light: a truncated
// series can dip below zero where the field is peaked); false: the linear
// response itself (the near-star term's B, diffuse/near_star.h). The grid's
// per-view pass and its marcher's near-star term call it (raycast/).
template <int kDeg, bool kZonal, class Scene>
NEBULA_HD void field_scattered_light(const Scene& s, const DiffuseView& f, float tau_v, size_t cell, Vec3 point,
                                     Vec3 to_eye, float (&light)[kMaxBands], float (&peak)[kMaxBands],
                                     bool clamp = true, int deg = kDeg) {
  float D[kMaxBands][kDeg + 1];
  f.project<kDeg>(cell, to_eye, D, deg);
  if constexpr (kZonal) {
    if (zonal_scattered_light<kDeg>(s, f, tau_v, cell, point, to_eye, D, light, peak, deg, clamp)) return;
  }
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < s.n_bands && f.has[b]) {
      // The own response's peak, as DiffuseView::peak gives it (w = 0).
      const float v = f.scattered<kDeg>(b, s.albedo[b] * tau_v * s.extinction_ratio[b], D[b], &peak[b], deg);
      light[b] = clamp ? fmaxf(0.0f, v) : v;
    }
}

}  // namespace nebula
