#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/test_support.h"
#include "spectral/spectral_test_scene.h"
#include "tables/test_tables.h"

namespace nebula::spectral {
namespace {

// The largest |cpu - gpu| over all planes, relative to the largest |cpu| (> 0).
double largest_difference(const Image& cpu, const Image& gpu) {
  double peak = 0, worst = 0;
  for (size_t i = 0; i < cpu.pixels.size(); ++i) {
    peak = std::max(peak, double(std::fabs(cpu.pixels[i])));
    worst = std::max(worst, double(std::fabs(cpu.pixels[i] - gpu.pixels[i])));
  }
  EXPECT_GT(peak, 0.0);
  return worst / peak;
}

// The same march_spectral on both backends, every method (the voxel-light
// method's pre-pass too, voxel_light on both), without and with a table:
// accumulators agree to 1e-4 of
// their peak (float contraction moves voxel crossings by ulps).
TEST(SpectralRendererGpu, AgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  auto scene = testing::noise_scene(24, 0.6f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 64, 48);
  const auto f = testing::filters({"B", "V", "R"});
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, 0.6);
  for (SpectralMethod method : {SpectralMethod::Double, SpectralMethod::Analytic, SpectralMethod::Projection,
                                SpectralMethod::LightBasis, SpectralMethod::VoxelLight,
                                SpectralMethod::Preintegrated})
    for (int nodes : {0, 3}) {  // the thin limit; the table at 3 attenuations (docs/spectral.md, "Tables")
      SpectralSettings s;
      s.method = method;
      s.table_nodes = nodes;
      const SpectralModel m = build_spectral_model(f, {{41400}, {5770}}, s);
      SpectralRenderInputs in = scene.inputs(m);
      in.table = nodes > 0 ? &table : nullptr;
      // The star pixels' rays on both backends, except for the two methods whose every pair is costly on the
      // CPU (the double integral's wavelengths, the closed form's exponential integrals in double precision:
      // 16 s for this image's plain rays on two cores, minutes with the star pixels' thousands). The star
      // pixels' march is the same code for every method.
      in.star_pixels = method != SpectralMethod::Double && method != SpectralMethod::Analytic;
      const double d = largest_difference(render_spectral(in, Backend::Cpu), render_spectral(in, Backend::Cuda));
      std::printf("  method %d, %d table nodes: largest CPU-GPU difference %.3g of the peak\n", int(method), nodes, d);
      EXPECT_LT(d, 1e-4);
    }
}

// Light between voxels (synthetic, two stars, the table at 3 attenuations):
// the same terms (a TBB loop on the CPU, a kernel on the GPU) in the same march, every method,
// the voxel-light pre-pass included; accumulators agree to 1e-4 of their peak.
TEST(SpectralRendererGpu, LightBetweenVoxelsAgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  auto scene = testing::noise_scene(24, 0.6f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 64, 48);
  const auto f = testing::filters({"B", "V", "R"});
  const ScatteringTable table = nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, 0.6);
  for (SpectralMethod method : {SpectralMethod::Double, SpectralMethod::Analytic, SpectralMethod::Projection,
                                SpectralMethod::LightBasis, SpectralMethod::VoxelLight,
                                SpectralMethod::Preintegrated}) {
    SpectralSettings s;
    s.method = method;
    s.table_nodes = 3;
    s.attenuation = method == SpectralMethod::Analytic ? Attenuation::Inverse : Attenuation::Law;
    const SpectralModel m = build_spectral_model(f, {{41400}, {5770}}, s);
    SpectralRenderInputs in = scene.inputs(m);
    in.table = &table;
    const SpectralDiffuseLight light = testing::synthetic_diffuse(scene, m);
    in.diffuse = &light;
    const double d = largest_difference(render_spectral(in, Backend::Cpu), render_spectral(in, Backend::Cuda));
    std::printf("  method %d with light between voxels: largest CPU-GPU difference %.3g of the peak\n", int(method), d);
    EXPECT_LT(d, 1e-4);
  }
}

// Albedo and g varying with wavelength, each table node its own (a, g): in
// the thin-voxel limit (the double integral taking them per wavelength too) and
// through node tables; accumulators agree to 1e-4 of their peak.
TEST(SpectralRendererGpu, VaryingAlbedoAndGAgreeWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  auto scene = testing::noise_scene(20, 0.6f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 48, 40);
  const auto f = testing::filters({"B", "V", "R"});
  for (SpectralMethod method : {SpectralMethod::Double, SpectralMethod::Projection, SpectralMethod::LightBasis,
                                SpectralMethod::VoxelLight, SpectralMethod::Preintegrated})
    for (bool with_tables : {false, true}) {
      if (with_tables && method == SpectralMethod::Double) continue;  // the thin limit only
      SpectralSettings s;
      s.method = method;
      s.table_nodes = 3;
      s.curve_um = {0.35, 0.9};
      s.curve_albedo = {0.4, 0.8};
      s.curve_g = {0.7, 0.4};
      const SpectralModel m = build_spectral_model(f, {{41400}, {5770}}, s);
      SpectralRenderInputs in = scene.inputs(m);
      std::vector<ScatteringTable> own;  // each node's table: the test shape at its g, labelled with its albedo
      if (with_tables)
        for (size_t k = 0; k < 3; ++k) {
          own.push_back(nebula::testing::make_test_table(5.0, 501, AngularBinning::UniformTheta, 90, m.node_g[k]));
          own.back().albedo = m.node_albedo[k];
        }
      for (const ScatteringTable& t : own) in.node_tables.push_back(&t);
      const double d = largest_difference(render_spectral(in, Backend::Cpu), render_spectral(in, Backend::Cuda));
      std::printf("  method %d, varying albedo and g, %s: largest CPU-GPU difference %.3g of the peak\n", int(method),
                  with_tables ? "node tables" : "thin limit", d);
      EXPECT_LT(d, 1e-4);
    }
}

// Emission (a line and a continuum, one weighted by a grid, one by tau_V)
// with two stars: the resolved images agree to 1e-4 of each filter's peak.
TEST(SpectralRendererGpu, EmissionAgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  auto scene = testing::noise_scene(20, 0.6f, {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}}, 48, 40);
  std::vector<float> weight(scene.grid.tau_v.size());
  for (size_t i = 0; i < weight.size(); ++i) weight[i] = 0.1f * float(i % 5);
  const auto f = testing::filters({"B", "V", "R"});
  for (SpectralMethod method : {SpectralMethod::Double, SpectralMethod::Analytic, SpectralMethod::Projection,
                                SpectralMethod::LightBasis, SpectralMethod::VoxelLight,
                                SpectralMethod::Preintegrated}) {
    SpectralSettings s;
    s.method = method;
    s.attenuation = method == SpectralMethod::Analytic ? Attenuation::Inverse : Attenuation::Law;
    const SpectralModel m = build_spectral_model(f, {{41400}, {5770}}, s, {{0.6563}, {0.0, {0.5, 1.0}, 0.4, 0.8}});
    SpectralRenderInputs in = scene.inputs(m);
    in.emission = {{&weight, 1.0f}, {nullptr, 2.0f}};
    const Image cpu = resolve_filters(render_spectral(in, Backend::Cpu), m);
    const Image gpu = resolve_filters(render_spectral(in, Backend::Cuda), m);
    const size_t plane = cpu.plane_size();
    for (size_t b = 0; b < cpu.bands.size(); ++b) {
      double peak = 0, worst = 0;
      for (size_t i = b * plane; i < (b + 1) * plane; ++i) {
        peak = std::max(peak, double(std::fabs(cpu.pixels[i])));
        worst = std::max(worst, double(std::fabs(cpu.pixels[i] - gpu.pixels[i])));
      }
      std::printf("  method %d, %s: largest CPU-GPU difference %.3g of the peak\n", int(method), cpu.bands[b].c_str(),
                  worst / peak);
      EXPECT_GT(peak, 0.0);
      EXPECT_LT(worst, 1e-4 * peak);
    }
  }
}

}  // namespace
}  // namespace nebula::spectral
