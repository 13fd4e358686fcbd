#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/philox.h"
#include "illumination/filters.h"
#include "spectral/spectral_test_scene.h"
#include "tables/test_tables.h"

namespace nebula::spectral {
namespace {

using testing::filters;

Image render_with(const testing::SpectralTestScene& scene, const SpectralModel& m,
                  const ScatteringTable* table = nullptr, float g = 0.6f) {
  SpectralRenderInputs in = scene.inputs(m);
  in.table = table;
  in.g = g;
  return resolve_filters(render_spectral(in, Backend::Cpu), m);
}

// Largest relative error per pixel over pixels above 1e-3 of the peak.
double worst_relative(const Image& a, const Image& ref) {
  double peak = 0, worst = 0;
  for (float v : ref.pixels) peak = std::max(peak, double(v));
  for (size_t i = 0; i < ref.pixels.size(); ++i)
    if (ref.pixels[i] > 1e-3 * peak) worst = std::max(worst, double(std::fabs(a.pixels[i] - ref.pixels[i]) / ref.pixels[i]));
  return worst;
}

// A thin dust cube (tau_V 1e-5 per voxel): the light is single scattering of
// the unattenuated star, w * integral S kappa B (D ~ 0), the same for every
// method; and the image is not empty.
TEST(SpectralRenderer, ThinDustIsTheFilteredBlackBody) {
  auto scene = testing::noise_scene(8, 1e-5f, {{0.9f, 0.2f, 0.1f}}, 24, 16);
  SpectralSettings s;
  s.wavelengths = 4000;
  s.method = SpectralMethod::Double;
  const SpectralModel ref_model = build_spectral_model(filters({"B", "V", "R"}), {{41400}}, s);
  const Image ref = render_with(scene, ref_model);
  double peak = 0;
  for (float v : ref.pixels) peak = std::max(peak, double(v));
  EXPECT_GT(peak, 0.0);
  for (SpectralMethod m : {SpectralMethod::Analytic, SpectralMethod::Projection, SpectralMethod::LightBasis,
                           SpectralMethod::Preintegrated}) {
    s.method = m;
    const double err = worst_relative(render_with(scene, build_spectral_model(filters({"B", "V", "R"}), {{41400}}, s)), ref);
    std::printf("  method %d: largest pixel error %.2e against the double integral (M = 4000)\n", int(m), err);
    EXPECT_LT(err, m == SpectralMethod::LightBasis ? 2e-2 : 2e-3);
  }
}

// Noise dust (tau_V up to 1 per voxel of 16, ~8 across the cube): the
// projection's largest pixel error against the double integral, per basis
// size. With the relative basis (ours) 4 elements meet the issue's 1% per
// pixel; the report's absolute basis leaves dim pixels, lit through long
// optical paths, wrong by 100% (docs/spectral.md, "Relative projection").
TEST(SpectralRenderer, ProjectionErrorPerBasisSize) {
  auto scene = testing::noise_scene(16, 1.0f, {{0.1f, 0.2f, -0.1f}}, 32, 24);
  SpectralSettings s;
  s.method = SpectralMethod::Double;
  s.wavelengths = 1000;
  const auto f = filters({"B", "V", "R", "sdss_g"});
  const Image ref = render_with(scene, build_spectral_model(f, {{9700}}, s));
  s.method = SpectralMethod::Projection;
  double first = 0;
  for (int n = 1; n <= 4; ++n) {
    s.basis = n;
    const double err = worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, s)), ref);
    std::printf("  projection, %d elements: largest pixel error %.2e\n", n, err);
    if (n == 1) first = err;
    if (n == 4) {
      EXPECT_LT(err, 0.1 * first);
      EXPECT_LT(err, 1e-2);
    }
  }
  s.relative = false;
  const double absolute = worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, s)), ref);
  std::printf("  absolute (the report's) basis, 4 elements: largest pixel error %.2e\n", absolute);
  EXPECT_GT(absolute, 0.1);
}

// The voxel-light method (per-view pre-pass, one set of F accumulators for any
// number of stars) against the double integral (M = 400) with one star and with
// six of different temperatures: within the issue's 1% per pixel with 4
// elements. Its error is the projection of e^(-kappa D_eye) alone plus the
// pre-pass' first-order expansion of 1/r^2 and the phase across a voxel; the
// nearer a star the larger the second one, hence the exact pairs within
// near_voxels (printed: the error without them).
TEST(SpectralRenderer, VoxelLightMeetsTheGoalWithOneAndSixStars) {
  const std::vector<Vec3> where{{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}, {0.2f, -0.3f, 0.1f},
                                {-0.1f, 0.3f, -0.3f}, {0.3f, 0.1f, 0.3f},  {0.0f, -0.1f, 0.0f}};
  const std::vector<SpectralStar> temps{{41400}, {31400}, {15700}, {9700}, {5770}, {3850}};
  const auto f = filters({"B", "V", "R", "sdss_g"});
  for (int n_stars : {1, 6}) {
    auto scene = testing::noise_scene(48, 1.0f / 3, std::vector<Vec3>(where.begin(), where.begin() + n_stars), 32, 24);
    const std::vector<SpectralStar> stars(temps.begin(), temps.begin() + n_stars);
    SpectralSettings s;
    s.attenuation = Attenuation::Law;
    s.method = SpectralMethod::Double;
    s.wavelengths = 400;
    const Image ref = render_with(scene, build_spectral_model(f, stars, s));
    s.method = SpectralMethod::VoxelLight;
    for (double near : {0.0, 4.0, 6.0, 10.0}) {
      s.near_voxels = near;
      const double err = worst_relative(render_with(scene, build_spectral_model(f, stars, s)), ref);
      std::printf("  voxel light, %d star(s), near_voxels %.0f: largest pixel error %.2e\n", n_stars, near, err);
      if (near == SpectralSettings{}.near_voxels) {
        EXPECT_LT(err, 1e-2);
      }
    }
  }
}

// With one star the voxel-light image is the projection's within their
// projection errors (each below 1% of the double integral, above).
TEST(SpectralRenderer, VoxelLightWithOneStarIsTheProjection) {
  auto scene = testing::noise_scene(48, 1.0f / 3, {{0.1f, 0.2f, -0.1f}}, 32, 24);
  SpectralSettings s;
  s.attenuation = Attenuation::Law;
  const auto f = filters({"B", "V", "R"});
  const Image projection = render_with(scene, build_spectral_model(f, {{9700}}, s));
  s.method = SpectralMethod::VoxelLight;
  const Image voxel = render_with(scene, build_spectral_model(f, {{9700}}, s));
  const double diff = worst_relative(voxel, projection);
  std::printf("  voxel light against the projection, one star: largest pixel difference %.2e\n", diff);
  EXPECT_LT(diff, 2e-2);
  double peak = 0;
  for (float v : projection.pixels) peak = std::max(peak, double(v));
  EXPECT_GT(peak, 0.0);
}

// A filter change on a fixed basis range: the same accumulators resolved with
// the new filters equal a fresh render with them.
TEST(SpectralRenderer, FilterChangeNeedsNoNewMarch) {
  auto scene = testing::noise_scene(12, 0.5f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 20, 20);
  SpectralSettings s;
  s.method = SpectralMethod::LightBasis;
  s.lo_um = 0.3;
  s.hi_um = 1.0;
  std::vector<SpectralStar> stars{{41400}, {3850}};
  SpectralModel m = build_spectral_model(filters({"B", "V"}), stars, s);
  const Image acc = render_spectral(scene.inputs(m), Backend::Cpu);
  set_filters(m, filters({"sdss_r", "F606W"}));
  const Image changed = resolve_filters(acc, m);
  const Image fresh = render_with(scene, build_spectral_model(filters({"sdss_r", "F606W"}), stars, s));
  ASSERT_EQ(changed.bands, fresh.bands);
  for (size_t i = 0; i < fresh.pixels.size(); ++i) EXPECT_NEAR(changed.pixels[i], fresh.pixels[i], 1e-5f * (1 + fresh.pixels[i]));
  EXPECT_THROW(set_filters(m, filters({"sdss_z"})), Error);  // reaches 1.11 um, past the basis range
}

// Pre-integration holds the filters in its tables: a filter change rebuilds
// them (no bake) and the march runs again, giving the fresh model's image.
TEST(SpectralRenderer, PreintegratedFilterChangeRebuildsItsTables) {
  auto scene = testing::noise_scene(12, 0.5f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 20, 20);
  SpectralSettings s;
  s.method = SpectralMethod::Preintegrated;
  s.lo_um = 0.3;
  s.hi_um = 1.0;
  std::vector<SpectralStar> stars{{41400}, {3850}};
  SpectralModel m = build_spectral_model(filters({"B", "V"}), stars, s);
  set_filters(m, filters({"sdss_r", "F606W"}));
  const Image changed = render_with(scene, m);
  const Image fresh = render_with(scene, build_spectral_model(filters({"sdss_r", "F606W"}), stars, s));
  ASSERT_EQ(changed.bands, fresh.bands);
  for (size_t i = 0; i < fresh.pixels.size(); ++i) EXPECT_EQ(changed.pixels[i], fresh.pixels[i]);
}


// A table that is exactly the thin limit, P = tau_sct p_HG (isotropic, so that
// the lookup's interpolation in angle is exact too): every method at every
// node count gives the thin-limit image, to float rounding. The nodes'
// polynomial in kappa is then the constant it should be.
TEST(SpectralRendererTables, AThinTableGivesTheThinImage) {
  ScatteringTable thin = ScatteringTable::make_axes(8.0, 9, AngularBinning::UniformMu, 12);
  thin.albedo = 0.6;
  thin.g = 0.0;
  for (int i = 0; i < thin.n_tau(); ++i)
    for (int k = 0; k < thin.n_mu(); ++k) thin.P[thin.index(i, k)] = float(thin.tau[i] / (4.0 * kPiD));
  nebula::testing::finish_table(thin);
  auto scene = testing::noise_scene(12, 0.8f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 20, 16);
  for (SpectralMethod method : {SpectralMethod::Double, SpectralMethod::Analytic, SpectralMethod::Projection,
                                SpectralMethod::LightBasis, SpectralMethod::VoxelLight, SpectralMethod::Preintegrated}) {
    SpectralSettings s;
    s.method = method;
    s.wavelengths = 40;
    s.depth_nodes = 256;  // the tables' size does not matter here; their build time does
    const Image reference = render_with(scene, build_spectral_model(filters({"B", "V", "R"}), {{41400}, {5770}}, s),
                                        nullptr, 0.0f);
    double peak = 0;
    for (float v : reference.pixels) peak = std::max(peak, double(v));
    ASSERT_GT(peak, 0.0);
    for (int nodes : {1, 2, kMaxTableNodes}) {
      s.table_nodes = nodes;
      const Image tabled =
          render_with(scene, build_spectral_model(filters({"B", "V", "R"}), {{41400}, {5770}}, s), &thin, 0.0f);
      double worst = 0;
      for (size_t i = 0; i < reference.pixels.size(); ++i)
        worst = std::max(worst, double(std::fabs(tabled.pixels[i] - reference.pixels[i])));
      EXPECT_LT(worst, 2e-5 * peak) << "method " << int(method) << ", " << nodes << " nodes";
    }
  }
}

// A table whose P / tau_sct falls with depth (the voxel's own extinction and
// multiple scattering: P = 0.73 (1 - e^-tau_sct) p_HG), on dust of tau_V up to
// 1 per voxel: the double integral reads it at each wavelength's own depth
// (the reference); the nodes interpolate P / kappa in kappa between a few
// depths. With bases large enough that their own error is small here (U to I),
// the error against it is within 1% per pixel from 2 nodes with the
// projection, the light-density basis and voxel light, and falls with 3 (the
// default) to the basis' own error (the projection's: 3e-4); one node (the V
// band's depth for every wavelength) is 9% off.
TEST(SpectralRendererTables, NodesAgainstTheDoubleIntegral) {
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, 0.6);
  auto scene = testing::noise_scene(16, 1.0f, {{0.1f, 0.2f, -0.1f}}, 32, 24);
  const auto f = filters({"U", "B", "V", "R", "I"});
  SpectralSettings s;
  s.attenuation = Attenuation::Law;
  s.method = SpectralMethod::Double;
  s.wavelengths = 400;
  const Image thin = render_with(scene, build_spectral_model(f, {{9700}}, s));
  s.table_nodes = 2;  // the Double method reads the table at every wavelength, whatever the nodes
  const Image ref = render_with(scene, build_spectral_model(f, {{9700}}, s), &table);
  const double change = worst_relative(thin, ref);
  std::printf("  the table against the thin limit: largest pixel change %.3f\n", change);
  EXPECT_GT(change, 0.1);
  for (SpectralMethod method : {SpectralMethod::Projection, SpectralMethod::LightBasis, SpectralMethod::VoxelLight,
                                SpectralMethod::Preintegrated}) {
    s.method = method;
    s.basis = method == SpectralMethod::LightBasis ? 8 : 6;
    s.depth_nodes = 1024;
    s.table_nodes = 0;
    s.near_voxels = 10;
    std::printf("  method %d without a table: largest pixel error %.2e against the thin double integral\n",
                int(method), worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, s)), thin));
    double errors[kMaxTableNodes + 1] = {};
    for (int nodes = 0; nodes <= 3; ++nodes) {
      s.table_nodes = nodes;
      errors[nodes] = worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, s), &table), ref);
      std::printf("  method %d, %d table nodes: largest pixel error %.2e against the double integral\n", int(method),
                  nodes, errors[nodes]);
    }
    EXPECT_GT(errors[0], 0.1);  // without the table
    EXPECT_GT(errors[1], 2e-2);
    EXPECT_LT(errors[2], 1e-2);
    EXPECT_LT(errors[3], errors[2]);
    if (method == SpectralMethod::Projection) {
      EXPECT_LT(errors[3], 1e-3);
    }
  }
}

// The nodes at the dust parameters users change: albedo 0.3 and 0.9 (the
// scattering depth a tau_V kappa, hence how far P/kappa bends over the filters'
// range, grows with it) and g 0 and 0.9 (the table's angular shape), with the
// projection (N = 6, U to I, tau_V up to 1 per voxel): 3 nodes (the default)
// within 1% per pixel of the double integral everywhere.
TEST(SpectralRendererTables, NodesHoldAtOtherAlbedosAndG) {
  auto scene = testing::noise_scene(16, 1.0f, {{0.1f, 0.2f, -0.1f}}, 32, 24);
  const auto f = filters({"U", "B", "V", "R", "I"});
  for (float albedo : {0.3f, 0.9f})
    for (float g : {0.0f, 0.9f}) {
      ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, g);
      table.albedo = albedo;
      SpectralSettings s;
      s.attenuation = Attenuation::Law;
      s.method = SpectralMethod::Double;
      s.wavelengths = 400;
      s.table_nodes = 3;
      SpectralRenderInputs in;
      const auto render = [&](const SpectralModel& m) {
        in = scene.inputs(m);
        in.table = &table;
        in.albedo = albedo;
        in.g = g;
        return resolve_filters(render_spectral(in, Backend::Cpu), m);
      };
      const Image ref = render(build_spectral_model(f, {{9700}}, s));
      s.method = SpectralMethod::Projection;
      s.basis = 6;
      s.depth_nodes = 1024;
      double errors[kMaxTableNodes + 1] = {};
      for (int nodes : {2, 3}) {
        s.table_nodes = nodes;
        errors[nodes] = worst_relative(render(build_spectral_model(f, {{9700}}, s)), ref);
      }
      std::printf("  albedo %.1f, g %.1f: largest pixel error %.2e (2 nodes), %.2e (3 nodes)\n", albedo, g, errors[2],
                  errors[3]);
      EXPECT_LT(errors[3], 1e-2) << "albedo " << albedo << ", g " << g;
      EXPECT_LT(errors[3], errors[2]) << "albedo " << albedo << ", g " << g;
    }
}

// The nodes' table (every node's value in one 16-byte cell per row and bin,
// rows in V-band depth) against each node's own lookup, at random depths (past
// the table's end too, where both clamp) and angles, albedo 0.3 and 0.9: within
// the table's own interpolation error there, a quarter of the largest second
// difference of the rows around the node's depth (a linear interpolant at no
// more than the table's spacing of a function with one kink per row).
TEST(SpectralRendererTables, NodeTableAgreesWithEachNodesLookup) {
  auto scene = testing::noise_scene(8, 0.5f, {{0.1f, 0.2f, -0.1f}}, 8, 8);
  for (float albedo : {0.3f, 0.9f}) {
    ScatteringTable table = nebula::testing::make_test_table(5.0, 201, AngularBinning::UniformTheta, 36, 0.6);
    table.albedo = albedo;
    SpectralSettings s;
    s.attenuation = Attenuation::Law;
    s.table_nodes = 3;
    const SpectralModel m = build_spectral_model(filters({"U", "B", "V", "R", "I"}), {{9700}}, s);
    SpectralRenderInputs in = scene.inputs(m);
    in.table = &table;
    in.albedo = albedo;
    SpectralSceneView view = view_of(m);
    set_table(view, in, table.P.data(), nullptr);
    const NodeTable nodes = node_table(in, view);
    ASSERT_FALSE(nodes.values.empty());
    use_node_table(view, nodes, nodes.values.data());
    const TableView t = nebula::view_of(table);
    uint64_t counter = 0;
    double worst = 0;
    for (int trial = 0; trial < 4000; ++trial) {
      const auto r = philox_uniform4(5, counter++, 0, 0, 0);
      const float tau_v = 25.0f * r.u0 * r.u0, u = t.angle_coordinate(2.0f * r.u1 - 1.0f);
      float fused[4];
      node_table_values(view, tau_v, u, fused);
      for (int k = 0; k < view.n_nodes; ++k) {
        const float tau_sct = albedo * tau_v * view.node_kappa[k];
        const float direct = t.lookup_at(tau_sct, u);
        const int row = std::min(int(tau_sct / t.tau_max * (t.n_tau - 1)), t.n_tau - 1);
        double first = 0, second = 0;
        for (int j = std::max(1, row - 1); j <= std::min(t.n_tau - 2, row + 2); ++j)
          for (int b = 0; b < t.n_mu; ++b) {
            first = std::max(first, double(std::fabs(t.at(j + 1, b) - t.at(j, b))));
            second = std::max(second, double(std::fabs(t.at(j + 1, b) - 2 * t.at(j, b) + t.at(j - 1, b))));
          }
        if (row >= t.n_tau - 3)  // the kink where the lookups clamp at the table's end (slope to 0)
          for (int b = 0; b < t.n_mu; ++b)
            second = std::max(second, double(std::fabs(t.at(t.n_tau - 1, b) - t.at(t.n_tau - 2, b))));
        // Plus float rounding: of the row coordinate (~1e-7 of the row index, times a row's
        // step in P) and of the values through two interpolations.
        const double bound = 0.25 * second + 1e-6 * (row + 1) * first + 4e-6 * std::fabs(direct);
        if (direct > 1e-3f) worst = std::max(worst, std::fabs(double(fused[k]) - direct) / double(direct));
        EXPECT_LE(std::fabs(double(fused[k]) - direct), bound)
            << "albedo " << albedo << " tau_V " << tau_v << " node " << k << " u " << u;
      }
    }
    std::printf("  albedo %.1f: %d rows of the nodes' table; largest relative difference (P > 1e-3) %.2e\n", albedo, nodes.rows,
                worst);
  }
}

// The analytic integral (Algorithm 1, kappa = C_T / lambda) takes the nodes'
// powers of kappa as lower powers of lambda: with the table it agrees with the
// double integral as the projection does.
TEST(SpectralRendererTables, AnalyticTakesTheNodes) {
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, 0.6);
  auto scene = testing::noise_scene(8, 1.0f, {{0.1f, 0.2f, -0.1f}}, 12, 10);
  const auto f = filters({"B", "V"});
  SpectralSettings s;
  s.method = SpectralMethod::Double;
  s.wavelengths = 400;
  s.table_nodes = 3;
  const Image ref = render_with(scene, build_spectral_model(f, {{9700}}, s), &table);
  s.method = SpectralMethod::Analytic;
  const double err = worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, s), &table), ref);
  std::printf("  analytic, 3 table nodes: largest pixel error %.2e\n", err);
  EXPECT_LT(err, 5e-3);
}

// Hard cases with the table: a voxel of tau_V = 1000 (its scattering depth
// beyond the table's range, so the lookup clamps) and a star inside the grid:
// every method gives finite, non-negative pixels.
TEST(SpectralRendererTables, ADenseVoxelStaysFinite) {
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 51, AngularBinning::UniformTheta, 36, 0.6);
  auto scene = testing::noise_scene(8, 0.5f, {{0.05f, 0.05f, 0.05f}}, 16, 12);
  scene.grid.tau_v[scene.grid.shape.index(4, 4, 4)] = 1000.0f;
  scene.bake = bake_star_depths_cpu(scene.grid, scene.star_positions);
  for (SpectralMethod method : {SpectralMethod::Double, SpectralMethod::Analytic, SpectralMethod::Projection,
                                SpectralMethod::LightBasis, SpectralMethod::VoxelLight, SpectralMethod::Preintegrated}) {
    SpectralSettings s;
    s.method = method;
    s.table_nodes = 3;
    s.depth_nodes = 256;
    const Image img = render_with(scene, build_spectral_model(filters({"B", "V"}), {{9700}}, s), &table);
    double peak = 0;
    for (float v : img.pixels) {
      ASSERT_TRUE(std::isfinite(v)) << "method " << int(method);
      EXPECT_GE(v, -1e-6f * float(peak + 1.0));
      peak = std::max(peak, double(v));
    }
    EXPECT_GT(peak, 0.0) << "method " << int(method);
  }
}

// A table for other dust than the render's, or nodes past the limit: refused.
TEST(SpectralRendererTables, RefusesAMismatchedTableAndTooManyNodes) {
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 11, AngularBinning::UniformMu, 36, 0.3);
  auto scene = testing::noise_scene(6, 0.5f, {{0.1f, 0.2f, -0.1f}}, 8, 8);
  SpectralSettings s;
  s.table_nodes = 2;
  const SpectralModel m = build_spectral_model(filters({"V"}), {{9700}}, s);
  SpectralRenderInputs in = scene.inputs(m);
  in.table = &table;  // g = 0.3, the dust's 0.6
  try {
    render_spectral(in, Backend::Cpu);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("g 0.3"), std::string::npos) << e.what();
  }
  s.table_nodes = kMaxTableNodes + 1;
  EXPECT_THROW(build_spectral_model(filters({"V"}), {{9700}}, s), Error);
}


// Albedo and g varying with wavelength (docs/spectral.md, "Albedo and g with
// wavelength"), in the thin-voxel limit, where the double integral takes them
// at each of its wavelengths exactly: each table node scatters with its own
// (a, g) and the nodes' polynomial in kappa carries them between. Dust whose
// albedo rises 0.55 -> 0.65 and whose g falls 0.65 -> 0.5 from 350 to 900 nm
// (piecewise linear, as a user's curve is), U to I, tau_V up to 1 per voxel:
// the error falls with the nodes (27%, 7%, 1.5%, 0.8% for 1-4 here; the
// curves' kinks slow it); with 4 every method stays within 2% per pixel (0.8-1.0%
// here). A curve that is constant gives the constant dust's image.
TEST(SpectralRendererVarying, AlbedoAndGAgainstTheDoubleIntegral) {
  auto scene = testing::noise_scene(12, 1.2f, {{0.1f, 0.2f, -0.1f}}, 24, 18);
  const auto f = filters({"U", "B", "V", "R", "I"});
  SpectralSettings s;
  s.attenuation = Attenuation::Law;
  s.curve_um = {0.35, 0.55, 0.90};
  s.curve_albedo = {0.55, 0.60, 0.65};
  s.curve_g = {0.65, 0.60, 0.50};
  s.method = SpectralMethod::Double;
  s.wavelengths = 400;
  s.table_nodes = 3;  // the double integral takes the curves at every wavelength, whatever the nodes
  const Image ref = render_with(scene, build_spectral_model(f, {{9700}}, s));
  SpectralSettings flat = s;  // the dust of the curves at 550 nm everywhere
  flat.curve_um.clear();
  flat.curve_albedo.clear();
  flat.curve_g.clear();
  flat.table_nodes = 0;
  const double change = worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, flat), nullptr, 0.6f), ref);
  std::printf("  the curves against constant dust (a = g = 0.6): largest pixel change %.3f\n", change);
  EXPECT_GT(change, 0.1);
  for (SpectralMethod method : {SpectralMethod::Projection, SpectralMethod::LightBasis, SpectralMethod::VoxelLight,
                                SpectralMethod::Preintegrated}) {
    s.method = method;
    s.basis = method == SpectralMethod::LightBasis ? 8 : 6;
    const bool all = method == SpectralMethod::Projection || method == SpectralMethod::Preintegrated;
    double errors[kMaxTableNodes + 1] = {};
    for (int nodes = all ? 1 : kMaxTableNodes; nodes <= kMaxTableNodes; ++nodes) {
      s.table_nodes = nodes;
      errors[nodes] = worst_relative(render_with(scene, build_spectral_model(f, {{9700}}, s)), ref);
      std::printf("  method %d, %d nodes: largest pixel error %.2e against the double integral\n", int(method), nodes,
                  errors[nodes]);
    }
    if (all) {
      EXPECT_LT(errors[2], errors[1]);
      EXPECT_LT(errors[3], errors[2]);
      EXPECT_LE(errors[4], errors[3]);
    }
    EXPECT_LT(errors[4], 2e-2);
  }
  // Constant curves: the same image as the constant dust, through a table and without.
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, 0.6);
  s.method = SpectralMethod::Projection;
  s.basis = 4;
  s.table_nodes = 3;
  s.curve_albedo = {0.6, 0.6, 0.6};
  s.curve_g = {0.6, 0.6, 0.6};
  const SpectralModel varying = build_spectral_model(f, {{9700}}, s);
  flat = s;
  flat.curve_um.clear();
  flat.curve_albedo.clear();
  flat.curve_g.clear();
  const SpectralModel constant = build_spectral_model(f, {{9700}}, flat);
  SpectralRenderInputs in = scene.inputs(varying);
  in.node_tables = {&table, &table, &table};
  const Image a = resolve_filters(render_spectral(in, Backend::Cpu), varying);
  const Image b = render_with(scene, constant, &table);
  double worst = 0, peak = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    peak = std::max(peak, double(b.pixels[i]));
    worst = std::max(worst, double(std::fabs(a.pixels[i] - b.pixels[i])));
  }
  EXPECT_LT(worst, 1e-5 * peak);
}

// Bad curves, and the double integral with node tables, are refused.
TEST(SpectralRendererVarying, RefusesBadCurves) {
  const auto f = filters({"B", "V"});
  SpectralSettings s;
  s.table_nodes = 3;
  s.curve_um = {0.4, 0.7};
  s.curve_albedo = {0.5, 0.7};
  s.curve_g = {0.6};  // one value short
  EXPECT_THROW(build_spectral_model(f, {{9700}}, s), Error);
  s.curve_g = {0.6, 1.0};  // |g| = 1
  EXPECT_THROW(build_spectral_model(f, {{9700}}, s), Error);
  s.curve_g = {0.6, 0.5};
  s.curve_um = {0.7, 0.4};  // decreasing
  EXPECT_THROW(build_spectral_model(f, {{9700}}, s), Error);
  s.curve_um = {0.4, 0.7};
  s.table_nodes = 0;
  EXPECT_THROW(build_spectral_model(f, {{9700}}, s), Error);
  s.table_nodes = 3;
  s.method = SpectralMethod::Double;
  const SpectralModel m = build_spectral_model(f, {{9700}}, s);
  auto scene = testing::noise_scene(8, 0.5f, {{0.1f, 0.2f, -0.1f}}, 8, 8);
  SpectralRenderInputs in = scene.inputs(m);
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 101, AngularBinning::UniformTheta, 36, 0.6);
  in.node_tables = {&table, &table, &table};
  EXPECT_THROW(render_spectral(in, Backend::Cpu), Error);  // tables of the wrong albedo, and Double with tables
}

}  // namespace
}  // namespace nebula::spectral
