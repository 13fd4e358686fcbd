#pragma once
// The diffuse radiation field (docs/diffuse.md): per band, the light that has
// scattered at least once in *another* voxel, as it enters each voxel, in
// real spherical harmonics on a grid of cells (f x f x f voxels each):
//
//   L_k(cell) = integral over directions d of L_in(d) Y_k(d),  L_sun pc^-2,
//
// L_in(d) the radiance propagating along d that enters the cell's voxels
// (their own dust not yet crossed). A voxel responds to it through the
// Legendre moments of its own table (DESIGN.md section 3, "Table"):
//
//   p_l(tau_sct) = 2 pi integral P(tau_sct, mu) P_l(mu) d mu,
//
// and by the addition theorem the light it scatters towards the eye, per unit
// of chord / l as the direct term E P, is
//
//   S = integral L_in(d) P(tau_sct, d . e) dd = sum_l p_l(tau_sct) D_l,
//   D_l = sum over m of Y_lm(e) L_lm,   e the direction to the eye.
//
// The table holds the voxel's internal multiple scattering of this light as
// it does for starlight, so nothing is counted twice.
//
// Truncation, and the forward peak (delta-M, Wiscombe 1977, J. Atmos. Sci.
// 34, 1408). Dust scatters forwards (g = 0.6 to 0.9): the series above
// converges slowly, and cut at degree N it misplaces the peak's light by tens
// of percent at g = 0.9. So the voxel's response is split into a forward peak
// of strength p_{N+1} (a delta: light going on in its own direction) and the
// rest, p*_l = p_l - p_{N+1} for l <= N, whose series the field's harmonics
// answer. The peak's light is the radiance already travelling towards the
// eye: the marcher keeps it by attenuating the ray through the voxel by
// exp(-tau c / l) + p_{N+1} c / l instead of exp(-tau c / l) (raycast/).
// The field itself is peaked where light streams away from a star, and its
// truncated series rings (negative lobes behind the peak, which back-scatter
// into the image); the series is therefore cut with Lanczos sigma factors,
// sinc(l / (N + 1)), which smooth the field enough to damp the ringing
// (docs/diffuse.md gives the measured choice of degree and factors).
#include <cstddef>
#include <string>
#include <type_traits>
#include <vector>

#include "core/bands.h"
#include "core/device_mirror.h"
#include "core/grid.h"
#include "core/hd.h"
#include "diffuse/diffuse_taper.h"
#include "diffuse/spherical_harmonics.h"
#include "tables/scattering_table.h"

namespace nebula {

constexpr int kMaxDiffuseDegree = 4;  // the marchers keep sum_m per degree, 5 per band, in registers
constexpr int kMaxZonalStars = 4;     // stars whose light keeps zonal degrees (the brightest)

// A response row: p*_0..p*_degree and the peak, padded to whole vector loads.
NEBULA_HD constexpr int diffuse_response_stride(int degree) { return (degree + 2 + 3) / 4 * 4; }
// With zonal degrees a row holds two responses, each padded to whole vector
// loads: the zonal one (r_0..r_zonal, its peak p_{zonal+1}), then from
// diffuse_response_stride(zonal) on the harmonics' own (r_0..r_degree, p_{degree+1}).
NEBULA_HD constexpr int diffuse_zonal_stride(int degree, int zonal) {
  return diffuse_response_stride(zonal) + diffuse_response_stride(degree);
}

// Four floats at p (16-byte aligned): one vector load on the device.
struct Quad {
  float v[4];
};
NEBULA_HD Quad load_quad(const float* p) {
#if NEBULA_ON_DEVICE
  const float4 q = *reinterpret_cast<const float4*>(p);
  return {{q.x, q.y, q.z, q.w}};
#else
  return {{p[0], p[1], p[2], p[3]}};
#endif
}

// A kernel's view of a field, by value (host or device pointers). The
// harmonics of all bands are interleaved, [cell][k][band of 4]: one vector
// load per harmonic serves every band.
struct DiffuseView {
  GridShape cells;     // the field's cells; cell edge = 2^shift voxels
  int shift = 0;
  int degree = 0;      // l_max
  int coeffs = 1;      // per cell: (degree + 1)^2 harmonics, then the zonal blocks
  int zonal = 0, zonal_stars = 0;  // zonal degrees (0: none) and the stars that have them
  Vec3 zonal_star[kMaxZonalStars] = {};
  int stride = 4;      // floats per response row
  int own_at = 0;      // where the harmonics' own response starts in a row (after the zonal one)
  const float* packed = nullptr;          // [(cell * coeffs + k) * 4 + band]
  bool has[kMaxBands] = {};               // whether the band has a field (else its slots are 0)
  const float* response[kMaxBands] = {};  // [row * stride + own_at + l]: p*_0..p*_degree, the peak p_{degree+1} (and the zonal response before them)
  int rows[kMaxBands] = {};
  float rows_per_tau[kMaxBands] = {};     // (rows - 1) / the table's tau_max

  NEBULA_HD size_t cell_of(int x, int y, int z) const { return cells.index(x >> shift, y >> shift, z >> shift); }

  // D[b][l] = sum over m of Y_lm(e) L_lm of band b at `cell`, with e the
  // direction to the eye, for l <= deg (0 above). kDeg bounds deg at compile
  // time so that D stays in registers: the grid marcher's prepass passes its
  // field's degree as kDeg; the axial marcher, which projects per sample,
  // passes kMaxDiffuseDegree and the field's degree as deg.
  template <int kDeg>
  NEBULA_HD void project(size_t cell, Vec3 to_eye, float (&D)[kMaxBands][kDeg + 1], int deg = kDeg) const {
    constexpr int n_max = (kDeg + 1) * (kDeg + 1);
    const int n = (deg + 1) * (deg + 1);
    float y[n_max];
    sh_basis(deg, to_eye, y);
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b)
      NEBULA_UNROLL
      for (int l = 0; l <= kDeg; ++l) D[b][l] = 0.0f;
    const float* c = packed + cell * size_t(coeffs) * 4;
    NEBULA_UNROLL
    for (int k = 0; k < n_max; ++k) {
      if (k >= n) break;
      const Quad q = load_quad(c + 4 * k);
      const int l = sh_degree_of(k);
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b) D[b][l] += y[k] * q.v[b];
    }
  }

  // sum_l p*_l(tau_sct) D_l for band b, and the forward peak p_{N+1}(tau_sct)
  // in *peak (deg and kDeg as for project): the response, linear between table rows (clamped to the last
  // one, as the table lookup is). Both rows' sums are taken, then
  // interpolated: fewer operations than interpolating each moment.
  template <int kDeg>
  NEBULA_HD float scattered(int b, float tau_sct, const float (&D)[kDeg + 1], float* peak, int deg = kDeg) const {
    const float u = fminf(fmaxf(tau_sct * rows_per_tau[b], 0.0f), float(rows[b] - 1));
    int i = static_cast<int>(u);
    i = i > rows[b] - 2 ? rows[b] - 2 : i;
    const float f = u - float(i);
    const int own_stride = diffuse_response_stride(deg);
    const float* r0 = response[b] + size_t(i) * stride + own_at;
    float s[2] = {0.0f, 0.0f}, p[2] = {0.0f, 0.0f};
    NEBULA_UNROLL
    for (int row = 0; row < 2; ++row)
      NEBULA_UNROLL
      for (int q = 0; q < diffuse_response_stride(kDeg) / 4; ++q) {
        if (4 * q >= own_stride) break;
        const Quad r = load_quad(r0 + row * stride + 4 * q);
        NEBULA_UNROLL
        for (int j = 0; j < 4; ++j) {
          const int l = 4 * q + j;
          if (l <= deg) s[row] += r.v[j] * D[l <= kDeg ? l : kDeg];
          if (l == deg + 1) p[row] = r.v[j];
        }
      }
    *peak = p[0] + f * (p[1] - p[0]);
    return s[0] + f * (s[1] - s[0]);
  }

  // Band b's response row below tau_sct (the zonal response first when
  // there are zonal degrees; the row above it is `stride` floats on), and in
  // *frac where tau_sct lies between them (clamped to the table, as lookups are).
  NEBULA_HD const float* response_row(int b, float tau_sct, float* frac) const {
    const float u = fminf(fmaxf(tau_sct * rows_per_tau[b], 0.0f), float(rows[b] - 1));
    int i = static_cast<int>(u);
    i = i > rows[b] - 2 ? rows[b] - 2 : i;
    *frac = u - float(i);
    return response[b] + size_t(i) * stride;
  }

  // How much of a voxel's response at p, seen from to_eye (unit), is the
  // zonal one (docs/diffuse.md, "Zonal degrees"): all of it where the eye is
  // on the far side of the voxel from the brightest star (it sees light the
  // star's light scatters forwards and sideways, which the zonal degrees
  // resolve), none where the eye looks at the voxel's lit side from beyond
  // 120 degrees (light scattered back: the harmonics' own response), linear
  // in the cosine between. 0 without zonal degrees.
  NEBULA_HD float zonal_weight(Vec3 p, Vec3 to_eye) const {
    if (zonal == 0) return 0.0f;
    const Vec3 r = p - zonal_star[0];
    const float len = length(r);
    const float mu = len > 0.0f ? dot(r, to_eye) / len : 1.0f;
    return fminf(1.0f, fmaxf(0.0f, 2.0f * (mu + 0.5f)));  // (mu - cos 120) / (cos 90 - cos 120)
  }

  // The forward peak p_{N+1}(tau_sct) of band b alone (the marcher's
  // transmittance, any degree).
  // With zonal degrees, `zonal_w` (zonal_weight) blends it with the zonal
  // response's peak p_{zonal+1}.
  NEBULA_HD float peak(int b, float tau_sct, float zonal_w = 0.0f) const {
    const float u = fminf(fmaxf(tau_sct * rows_per_tau[b], 0.0f), float(rows[b] - 1));
    int i = static_cast<int>(u);
    i = i > rows[b] - 2 ? rows[b] - 2 : i;
    const float f = u - float(i);
    const float* r = response[b] + size_t(i) * stride + own_at + degree + 1;
    const float own = r[0] + f * (r[stride] - r[0]);
    if (!(zonal_w > 0.0f)) return own;
    const float* z = response[b] + size_t(i) * stride + zonal + 1;
    const float theirs = z[0] + f * (z[stride] - z[0]);
    return own + zonal_w * (theirs - own);
  }
};

// Calls f(std::integral_constant<int, degree>) for a field's degree, 0 to
// kMaxDiffuseDegree: the one place that turns it into a template argument.
template <class F>
decltype(auto) dispatch_diffuse_degree(int degree, F&& f) {
  switch (degree) {
    case 0: return f(std::integral_constant<int, 0>{});
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    default: break;
  }
  static_assert(kMaxDiffuseDegree == 4, "one case per degree");
  return f(std::integral_constant<int, 4>{});
}

// The owning field. Its harmonics live in `packed`, the kernels' layout; a
// band has a field when it has a response. A CUDA bake leaves them on the
// device only (device_packed, where the CUDA marchers read them): host code
// reads them through host_packed(), which downloads them the first time.
struct DiffuseField {
  GridShape cells;
  int shift = 0;   // a cell spans 2^shift voxels per axis
  int degree = 3;
  // Zonal degrees degree + 1 .. zonal (0: none) of the light from each of the
  // first zonal_stars stars, about the direction from the star to the cell.
  int zonal = 0;
  int zonal_stars = 0;
  Vec3 zonal_star[kMaxZonalStars] = {};
  std::vector<std::vector<float>> response;  // [band]: per table row, p*_0..p*_degree, the peak, padding (delta_m_response); empty: no field
  std::vector<float> response_tau_max;       // [band]
  // The device copy of the harmonics (core/device_mirror.h); changing them resets it.
  mutable DeviceMirror device_packed;
  // The device copies of the responses, uploaded on a frame's first use
  // (allocate resets them; a bake sets the responses once).
  mutable DeviceMirror device_response[kMaxBands];

  DiffuseField() = default;
  DiffuseField(const DiffuseField& other);  // shares the device copy: the harmonics are the same
  DiffuseField& operator=(const DiffuseField& other);
  DiffuseField(DiffuseField&&) = default;
  DiffuseField& operator=(DiffuseField&&) = default;

  int n_zonal() const { return zonal > degree ? zonal - degree : 0; }
  int n_coeffs() const { return sh_count(degree) + zonal_stars * n_zonal(); }
  int response_stride() const { return n_zonal() > 0 ? diffuse_zonal_stride(degree, zonal) : diffuse_response_stride(degree); }
  size_t n_bands() const { return response.size(); }
  bool has_band(size_t b) const { return b < response.size() && !response[b].empty(); }
  size_t packed_size() const { return cells.count() * size_t(n_coeffs()) * 4; }
  // Whether the harmonics are there, on the host or the device.
  bool has_harmonics() const;
  // Sizes the arrays for `bands` bands, harmonics all zero and no band with a
  // field yet; on_host = false: the harmonics will be made on the device.
  void allocate(size_t bands, bool on_host = true);
  // [(cell * n_coeffs + k) * 4 + band], 0 for bands without a field.
  const std::vector<float>& host_packed() const;
  // Band b's harmonics, [cell * n_coeffs + k] (copied out of / into the packed array).
  std::vector<float> band_coeffs(size_t b) const;
  void set_band_coeffs(size_t b, const std::vector<float>& coeffs);
  // The host array, for a producer on the host to write (resets the device copy).
  std::vector<float>& packed_for_writing();
  size_t bytes() const;       // what a kernel reads: the harmonics and the responses
  // Host pointers; without_harmonics: all but `packed` (for a placement to fill).
  DiffuseView view(bool without_harmonics = false) const;

 private:
  mutable std::vector<float> packed_;  // empty while only the device holds the harmonics
};

// p_0 .. p_n of every row of `table` (row-major, n + 1 per row): the table's
// bins are its averages over their mu ranges, so each bin contributes its
// value times the exact integral of P_l over the bin.
std::vector<double> legendre_moments(const ScatteringTable& table, int n);

// The response a field of this degree uses, per row (diffuse_response_stride
// values): p_l - peak for l <= N, then the forward peak p_{N+1} (0 where it is
// negative, in thick voxels that scatter mostly backwards), then zeros. With
// zonal > degree each row holds first the zonal response, p_l - p_{zonal+1}
// for l <= zonal and that peak, then the harmonics' own as above
// (diffuse_zonal_stride). The Lanczos taper (resolved_taper) multiplies each
// p_l - peak by sigma_l of its cut: it smooths the series' ringing but also
// its anisotropy, and so moves light between the directions the eye sees the
// field from (docs/diffuse.md, "Truncation").
std::vector<float> delta_m_response(const ScatteringTable& table, int degree, int zonal = 0,
                                    DiffuseTaper taper = DiffuseTaper::Auto);
// Lanczos's sigma factor of degree l in a series cut at `degree`: sinc(l / (degree + 1)), 1 at l = 0.
double lanczos_sigma(int l, int degree);

// The field's cells for a grid: the largest power-of-2 cell edge f (in
// voxels) with at least `cells` of them along the grid's longest axis (f = 1
// when the grid has no more), each axis covered by ceil(n / f) cells.
GridShape diffuse_cells(const GridShape& grid, int cells, int* shift);

}  // namespace nebula
