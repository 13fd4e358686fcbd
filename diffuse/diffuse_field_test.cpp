#include "diffuse/diffuse_field.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/math.h"
#include "montecarlo/henyey_greenstein.h"

namespace nebula {
namespace {

// The optically thin table P = tau_sct x (bin mean of p_HG), on n_mu uniform-theta bins.
ScatteringTable thin_table(double g, int n_mu, double tau_max = 2.0, int n_tau = 5) {
  ScatteringTable t = ScatteringTable::make_axes(tau_max, n_tau, AngularBinning::UniformTheta, n_mu);
  t.g = g;
  for (int i = 0; i < t.n_tau(); ++i)
    for (int k = 0; k < n_mu; ++k)
      t.P[t.index(i, k)] = static_cast<float>(t.tau[i] * hg_bin_mean(g, t.mu_edges[k], t.mu_edges[k + 1]));
  return t;
}

// p_l of an optically thin voxel is tau_sct g^l (the HG Legendre moments);
// the bins blur the forward peak a little, less with more of them.
TEST(DiffuseResponse, ThinTableGivesTheHgMoments) {
  for (double g : {0.0, 0.6, 0.9}) {
    const ScatteringTable t = thin_table(g, 720);
    const std::vector<double> p = legendre_moments(t, 4);
    ASSERT_EQ(p.size(), size_t(t.n_tau()) * 5);
    for (int i = 0; i < t.n_tau(); ++i)
      for (int l = 0; l <= 4; ++l) {
        const double expected = t.tau[i] * std::pow(g, l);
        // l = 0 is exact but for the table's float32 values (2^-24 relative
        // each): the bins' means times their widths add up to the whole.
        EXPECT_NEAR(p[size_t(i) * 5 + l], expected, l == 0 ? 4 * 0x1p-24 * (1 + expected) : 2e-3 * t.tau[i])
            << "g " << g << " row " << i << " l " << l;
      }
  }
}

// The delta-M split: a peak of p_{N+1}, the rest p_l - p_{N+1}, as it is
// or tapered by Lanczos's sigma factors; without zonal degrees the default
// (auto) leaves it as it is.
TEST(DiffuseResponse, DeltaMSplitsOffTheForwardPeak) {
  const ScatteringTable t = thin_table(0.9, 720);
  for (DiffuseTaper taper : {DiffuseTaper::None, DiffuseTaper::Lanczos})
  for (int degree = 0; degree <= kMaxDiffuseDegree; ++degree) {
    const std::vector<float> r = delta_m_response(t, degree, 0, taper);
    const auto sigma = [&](int l) { return taper == DiffuseTaper::Lanczos ? lanczos_sigma(l, degree) : 1.0; };
    const std::vector<double> p = legendre_moments(t, degree + 1);
    const int stride = diffuse_response_stride(degree);
    ASSERT_EQ(stride % 4, 0) << "rows are whole vector loads";
    ASSERT_GE(stride, degree + 2);
    ASSERT_EQ(r.size(), size_t(t.n_tau()) * stride);
    for (int i = 0; i < t.n_tau(); ++i) {
      const float* row = r.data() + size_t(i) * stride;
      for (int j = degree + 2; j < stride; ++j) EXPECT_EQ(row[j], 0.0f) << "padding";
      const double peak = p[size_t(i) * (degree + 2) + degree + 1];
      EXPECT_NEAR(row[degree + 1], peak, 1e-6 * (1 + peak));
      EXPECT_NEAR(row[degree + 1], t.tau[i] * std::pow(0.9, degree + 1), 2e-3 * t.tau[i]);
      for (int l = 0; l <= degree; ++l)
        EXPECT_NEAR(row[l], (p[size_t(i) * (degree + 2) + l] - peak) * sigma(l), 1e-6 * (1 + t.tau[i]))
            << to_string(taper) << " degree " << degree << " row " << i << " l " << l;
    }
  }
  EXPECT_EQ(delta_m_response(t, 3), delta_m_response(t, 3, 0, DiffuseTaper::None)) << "untapered by default";
  EXPECT_EQ(delta_m_response(t, 3, 0, DiffuseTaper::Auto), delta_m_response(t, 3, 0, DiffuseTaper::None));
  EXPECT_NE(delta_m_response(t, 3), delta_m_response(t, 3, 0, DiffuseTaper::Lanczos)) << "the taper changes the rows";
  EXPECT_THROW(delta_m_response(t, kMaxDiffuseDegree + 1), ParameterError);
}

// With zonal degrees a row holds two delta-M responses, each padded to whole
// vector loads: the zonal one cut at the zonal degree (its peak p_{K+1}),
// then the harmonics' own, exactly the row a field without zonal degrees has.
// The taper applies to both, each with the sigma factors of its own cut; with
// zonal degrees the default (auto) is the Lanczos taper.
TEST(DiffuseResponse, ZonalRowsHoldTheZonalResponseThenTheHarmonicsOwn) {
  const ScatteringTable t = thin_table(0.9, 720);
  const int degree = 3, zonal = 16;
  for (DiffuseTaper taper : {DiffuseTaper::None, DiffuseTaper::Lanczos}) {
  const std::vector<float> r = delta_m_response(t, degree, zonal, taper);
  const std::vector<float> own = delta_m_response(t, degree, 0, taper);
  const auto sigma = [&](int l) { return taper == DiffuseTaper::None ? 1.0 : lanczos_sigma(l, zonal); };
  const std::vector<double> p = legendre_moments(t, zonal + 1);
  const int stride = diffuse_zonal_stride(degree, zonal), own_at = diffuse_response_stride(zonal);
  ASSERT_EQ(stride % 4, 0);
  ASSERT_EQ(own_at % 4, 0);
  ASSERT_GE(own_at, zonal + 2);
  ASSERT_EQ(r.size(), size_t(t.n_tau()) * stride);
  const int own_stride = diffuse_response_stride(degree);
  for (int i = 0; i < t.n_tau(); ++i) {
    const float* row = r.data() + size_t(i) * stride;
    const double* m = p.data() + size_t(i) * (zonal + 2);
    const double peak = m[zonal + 1];
    EXPECT_NEAR(row[zonal + 1], peak, 1e-6 * (1 + peak));
    EXPECT_NEAR(row[zonal + 1], t.tau[i] * std::pow(0.9, zonal + 1), 2e-3 * t.tau[i]);
    for (int l = 0; l <= zonal; ++l)
      EXPECT_NEAR(row[l], (m[l] - peak) * sigma(l), 1e-6 * (1 + t.tau[i]))
          << to_string(taper) << " row " << i << " l " << l;
    for (int j = zonal + 2; j < own_at; ++j) EXPECT_EQ(row[j], 0.0f) << "padding";
    for (int j = 0; j < own_stride; ++j)
      EXPECT_EQ(row[own_at + j], own[size_t(i) * own_stride + j]) << "the harmonics' own response, row " << i;
  }
  }
  const std::vector<float> own = delta_m_response(t, degree);
  EXPECT_EQ(delta_m_response(t, degree, zonal), delta_m_response(t, degree, zonal, DiffuseTaper::Lanczos))
      << "auto: Lanczos where there are zonal degrees";
  EXPECT_EQ(resolved_taper(DiffuseTaper::Auto, 3, 24), DiffuseTaper::Lanczos);
  EXPECT_EQ(resolved_taper(DiffuseTaper::Auto, 4, 0), DiffuseTaper::None);
  EXPECT_EQ(resolved_taper(DiffuseTaper::None, 3, 24), DiffuseTaper::None);
  EXPECT_EQ(delta_m_response(t, degree, 0), own) << "no zonal degrees: the rows as before";
  EXPECT_THROW(delta_m_response(t, degree, kMaxZonalDegree + 1), ParameterError);
}

template <int kDeg>
void check_truncated_series(const ScatteringTable& t, DiffuseTaper taper) {
  const int degree = kDeg;
  DiffuseField f;
  f.degree = degree;
  f.cells.nx = f.cells.ny = f.cells.nz = 1;
  const Vec3 d0 = normalize(Vec3{0.3f, -0.5f, 0.8f}), e = normalize(Vec3{-0.2f, 0.1f, 0.9f});
  const float E = 2.5f;
  float y[kMaxShCoeffs];
  sh_basis(degree, d0, y);
  f.allocate(1);
  std::vector<float> c(y, y + sh_count(degree));
  for (float& v : c) v *= E;
  f.set_band_coeffs(0, c);
  f.response = {delta_m_response(t, degree, 0, taper)};
  f.response_tau_max = {float(t.tau_max())};
  const DiffuseView v = f.view();
  ASSERT_TRUE(v.has[0]);
  ASSERT_FALSE(v.has[1]);
  float D[kMaxBands][kDeg + 1];
  v.project<kDeg>(0, e, D);
  for (int b = 1; b < kMaxBands; ++b)
    for (int l = 0; l <= kDeg; ++l) EXPECT_EQ(D[b][l], 0.0f) << "a band without a field reads zeros";
  double p[kMaxDiffuseDegree + 2];
  legendre(kMaxDiffuseDegree + 1, dot(d0, e), p);
  for (double tau : {0.0, 0.25, 1.0, 1.3, 2.0}) {
    // Between rows the response is linear in tau, as the table is.
    const double peak = tau * std::pow(0.6, degree + 1);
    double expected = 0;
    for (int l = 0; l <= degree; ++l) {
      const double x = kPiD * l / (degree + 1);
      const double sigma = l == 0 || taper == DiffuseTaper::None ? 1.0 : std::sin(x) / x;
      expected += (2 * l + 1) / (4 * kPiD) * (tau * std::pow(0.6, l) - peak) * sigma * p[l];
    }
    float got_peak = -1;
    EXPECT_NEAR(v.scattered<kDeg>(0, float(tau), D[0], &got_peak), E * expected, 3e-3 * E * tau + 1e-6)
        << "degree " << degree << " tau " << tau;
    EXPECT_NEAR(got_peak, peak, 3e-3 * tau + 1e-7);
  }
  // Beyond the table the last row holds (as lookups clamp).
  float a = 0, b = 0;
  EXPECT_FLOAT_EQ(v.scattered<kDeg>(0, 5.0f, D[0], &a), v.scattered<kDeg>(0, 2.0f, D[0], &b));
  EXPECT_FLOAT_EQ(a, b);
}

// A parallel beam of irradiance E along d0 has harmonics E Y_k(d0); the
// voxel's response towards e must be E times the delta-M rest's Legendre
// series truncated at the field's degree, with Lanczos's factors where the
// taper asks for them (the addition theorem).
TEST(DiffuseResponse, ScatteredLightIsTheTruncatedLegendreSeries) {
  const ScatteringTable t = thin_table(0.6, 180, 2.0, 5);
  for (DiffuseTaper taper : {DiffuseTaper::None, DiffuseTaper::Lanczos})
    for (int degree = 0; degree <= kMaxDiffuseDegree; ++degree)
      dispatch_diffuse_degree(degree, [&](auto deg) { check_truncated_series<deg()>(t, taper); });
}

TEST(DiffuseCells, PowersOfTwoWithAtLeastTheCellsAsked) {
  GridShape g;
  g.nx = 256;
  g.ny = 128;
  g.nz = 100;
  g.voxel = 0.5f;
  int shift = -1;
  GridShape c = diffuse_cells(g, 64, &shift);
  EXPECT_EQ(shift, 2);
  EXPECT_EQ(c.nx, 64);
  EXPECT_EQ(c.ny, 32);
  EXPECT_EQ(c.nz, 25);
  EXPECT_FLOAT_EQ(c.voxel, 2.0f);
  c = diffuse_cells(g, 1000, &shift);
  EXPECT_EQ(shift, 0);
  EXPECT_EQ(c.nx, 256);
  g.nz = 101;
  c = diffuse_cells(g, 64, &shift);
  EXPECT_EQ(c.nz, 26);  // ceil(101 / 4)
  EXPECT_THROW(diffuse_cells(g, 0, &shift), ParameterError);
}

}  // namespace
}  // namespace nebula
