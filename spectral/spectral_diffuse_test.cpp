// Light between voxels in the spectral renderer (docs/spectral.md, "Light
// between voxels"): the per-voxel terms from the field's light at the table
// nodes (diffuse_voxel_terms) and the eye-side depth with the forward peak
// (diffuse_eye_depth), against their closed forms; the methods on the same
// light against the double integral. The pipeline's tests compare the light
// with the band renderer's (pipeline/spectral_render_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "spectral/spectral_test_scene.h"
#include "tables/test_tables.h"

namespace nebula::spectral {
namespace {

SpectralModel bvr_model(int nodes, SpectralMethod method = SpectralMethod::Projection) {
  const auto f = testing::filters({"B", "V", "R"});
  SpectralSettings s;
  s.method = method;
  s.table_nodes = nodes;
  return build_spectral_model(f, {{9700}}, s);
}

SpectralSceneView view_with_nodes(const SpectralModel& m) {
  SpectralSceneView v = view_of(m);
  v.n_nodes = int(m.node_kappa.size());
  return v;
}

// u(kappa) as the terms give it: e^(-kappa D) sum_p B_p (kappa - kappa_c)^p.
double u_of(const SpectralSceneView& v, const float* t, double kappa) {
  double sum = 0, x = 1;
  for (int p = 0; p < v.n_nodes; ++p, x *= kappa - v.kappa_center) sum += t[p] * x;
  return sum * std::exp(-kappa * t[v.n_nodes]);
}

// Light reddened by dust, u = A e^(-kappa D0): its rate is found from the
// outer nodes and the polynomial is the constant A, so u is exact between the
// nodes too; beyond kMaxDiffuseDepth the rest of the slope goes into the
// polynomial (exact at the nodes). A rising u (thin dust, light scattered
// twice: ~ kappa) has D = 0 and is its own polynomial.
TEST(SpectralDiffuse, TermsReproduceTheNodesAndAnExponential) {
  const SpectralModel m = bvr_model(3);
  const SpectralSceneView v = view_with_nodes(m);
  const float power[3] = {2.0f, 3.0f, 5.0f};
  for (double D0 : {0.0, 1.0, 2.5, 6.0}) {
    float H[3], t[4];
    for (int j = 0; j < 3; ++j) H[j] = float(power[j] * v.node_kappa[j] * 0.7 * std::exp(-v.node_kappa[j] * D0));
    diffuse_voxel_terms(v, H, power, t);
    EXPECT_NEAR(t[3], std::min(D0, double(kMaxDiffuseDepth)), 1e-4) << D0;
    for (int j = 0; j < 3; ++j) {
      const double expect = 0.7 * std::exp(-v.node_kappa[j] * D0);
      EXPECT_NEAR(u_of(v, t, v.node_kappa[j]), expect, 2e-5 * expect) << "node " << j << ", D0 " << D0;
    }
    if (D0 <= kMaxDiffuseDepth)
      for (double kappa = v.node_kappa[0]; kappa <= v.node_kappa[2]; kappa += 0.05) {
        const double expect = 0.7 * std::exp(-kappa * D0);
        EXPECT_NEAR(u_of(v, t, kappa), expect, 2e-5 * expect) << kappa << ", D0 " << D0;
      }
  }
  float H[3], t[4];
  for (int j = 0; j < 3; ++j) H[j] = power[j] * v.node_kappa[j] * (0.2f + 1.5f * v.node_kappa[j]);
  diffuse_voxel_terms(v, H, power, t);
  EXPECT_EQ(t[3], 0.0f);
  for (double kappa = v.node_kappa[0]; kappa <= v.node_kappa[2]; kappa += 0.05)
    EXPECT_NEAR(u_of(v, t, kappa), 0.2 + 1.5 * kappa, 1e-5);
  // No light (or a truncated series' negative light, clamped as the per-view pass does): nothing.
  const float dark[3] = {0.0f, -1.0f, 0.0f};
  diffuse_voxel_terms(v, dark, power, t);
  for (float x : t) EXPECT_EQ(x, 0.0f);
}

// The eye-side depth: the band marcher's transmittance e^(-tau) + peak over a
// whole voxel at the V band, for peaks that scale with kappa as a thin voxel's
// do (so pi(1) is the V band's); finite and within [0, tau] for any tau.
TEST(SpectralDiffuse, EyeDepthKeepsTheForwardPeakAtV) {
  const SpectralSceneView v = view_with_nodes(bvr_model(3));
  for (double tau : {1e-4, 0.01, 0.3, 1.0, 5.0, 30.0, 1000.0}) {
    const double c = 0.02 * std::min(tau, 1.0);  // the peak at kappa = 1
    float peak[3];
    for (int j = 0; j < 3; ++j) peak[j] = float(c * v.node_kappa[j]);
    const float t = diffuse_eye_depth(v, peak, float(tau));
    ASSERT_TRUE(std::isfinite(t)) << tau;
    EXPECT_GE(t, 0.0f);
    EXPECT_LE(t, float(tau));
    EXPECT_NEAR(std::exp(-double(t)), std::min(1.0, std::exp(-tau) + c), 2e-6 * std::max(1.0, tau)) << tau;
  }
  const float none[3] = {0, 0, 0};
  EXPECT_FLOAT_EQ(diffuse_eye_depth(v, none, 0.7f), 0.7f);
  EXPECT_EQ(diffuse_eye_depth(v, none, 0.0f), 0.0f);
}

// Every method on the same light between voxels (synthetic, two stars of
// different spectra, a table at 3 nodes): within 1% per pixel of the double
// integral (400 wavelengths), the light-density basis with 6 elements; and the
// light shows: it adds at least a tenth to the image. (The analytic integral
// takes the report's C_T / lambda, another light: its agreement with the
// double integral is the pipeline's FastMethodsAgainstTheDoubleIntegral.)
TEST(SpectralDiffuse, MethodsAgreeOnTheSameLight) {
  auto scene = testing::noise_scene(16, 0.5f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 32, 24);
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, 0.6);
  const auto f = testing::filters({"B", "V", "R"});
  const auto render = [&](SpectralMethod method, int basis, int wavelengths, bool diffuse) {
    SpectralSettings s;
    s.method = method;
    s.basis = basis;
    s.wavelengths = wavelengths;
    s.table_nodes = 3;
    const SpectralModel m = build_spectral_model(f, {{41400}, {3850}}, s);
    SpectralRenderInputs in = scene.inputs(m);
    in.table = &table;
    const SpectralDiffuseLight light = testing::synthetic_diffuse(scene, m);
    if (diffuse) in.diffuse = &light;
    return resolve_filters(render_spectral(in, Backend::Cpu), m);
  };
  const auto worst = testing::worst_relative_per_band;
  const Image ref = render(SpectralMethod::Double, 4, 400, true);
  const Image without = render(SpectralMethod::Double, 4, 400, false);
  double with_sum = 0, without_sum = 0;
  for (size_t i = 0; i < ref.pixels.size(); ++i) {
    with_sum += ref.pixels[i];
    without_sum += without.pixels[i];
  }
  EXPECT_GT(with_sum, 1.1 * without_sum);
  const double projection = worst(render(SpectralMethod::Projection, 4, 20, true), ref);
  const double light = worst(render(SpectralMethod::LightBasis, 6, 20, true), ref);
  const double voxel = worst(render(SpectralMethod::VoxelLight, 4, 20, true), ref);
  const double pre = worst(render(SpectralMethod::Preintegrated, 4, 20, true), ref);
  std::printf("  with light between voxels (%.0f%% of the image), largest pixel error against the double integral: "
              "projection (4) %.2e, light-density (6) %.2e, voxel light (4) %.2e, pre-integrated %.2e\n",
              100 * (1 - without_sum / with_sum), projection, light, voxel, pre);
  EXPECT_LT(pre, 1e-2);
  EXPECT_LT(projection, 1e-2);
  EXPECT_LT(light, 1e-2);
  EXPECT_LT(voxel, 1e-2);
}

}  // namespace
}  // namespace nebula::spectral
