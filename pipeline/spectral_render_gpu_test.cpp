// The spectral renderer's light between voxels on the GPU, through the
// pipeline: a CUDA per-view pass leaves its arrays on the device, where the
// CUDA renderer reads them and from where the CPU renderer downloads them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "core/test_support.h"
#include "pipeline/run_setup.h"
#include "pipeline/scene_bands.h"
#include "pipeline/spectral_scene.h"
#include "scene/scene_file.h"
#include "scene/test_files.h"
#include "tables/table_file.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

class SpectralSceneGpu : public testing::TempDirTest {
 protected:
  Scene scene(const std::vector<std::string>& overrides = {}) {
    write_table(testing::make_test_table(10.0, 1001, AngularBinning::UniformTheta, 180, 0.6), path("smooth.h5"), true);
    return load_scene(write_text("scene.toml", "bands = [\"B\", \"V\", \"R\"]\n"
                                               "[dust]\ntables = { B = \"smooth.h5\", V = \"smooth.h5\", R = \"smooth.h5\" }\n"
                                               "[density]\nprocedural = { n = 24, size_pc = 2.0 }\n"
                                               "[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
                                               "[[stars]]\nluminosity_lsun = 1e5\ntemperature_K = 3850\n"
                                               "position = [1.4, 1.0, 1.1]\n"
                                               "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\n"
                                               "width = 48\nheight = 40\n[render]\ndiffuse_photons = 262144\n"
                                               "[spectral]\nmethod = \"projection\"\nbasis = 4\n"),
                      overrides);
  }
};

double worst_of_peak(const Image& a, const Image& b) {
  double peak = 0, worst = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    peak = std::max(peak, double(std::fabs(a.pixels[i])));
    worst = std::max(worst, double(std::fabs(a.pixels[i] - b.pixels[i])));
  }
  EXPECT_GT(peak, 0.0);
  return worst / peak;
}

// The same per-view light (baked and projected on the GPU, left there) marched
// by both renderers: the CPU's downloads it. Accumulators agree to 1e-4 of
// their peak, as the renderers do on the same inputs (spectral_renderer_gpu_test).
TEST_F(SpectralSceneGpu, DeviceLightMarchedByBothBackends) {
  NEBULA_SKIP_WITHOUT_GPU();
  const Scene s = scene();
  const SceneBands bands = scene_bands(s);
  std::vector<std::pair<std::string, Passband>> filters;
  for (size_t b = 0; b < 3; ++b) filters.push_back({s.bands[b], bands.filters[b]});
  const spectral::SpectralModel m =
      spectral::build_spectral_model(filters, {{s.stars[0].temperature_K}, {s.stars[1].temperature_K}},
                                     spectral_settings(s));
  BakeResult bake = bake_star_depths(s.density, {s.stars[0].position, s.stars[1].position}, Backend::Cuda);
  const ScatteringTable table = testing::make_test_table(10.0, 1001, AngularBinning::UniformTheta, 180, 0.6);
  spectral::SpectralRenderInputs in;
  in.density = &s.density;
  in.model = &m;
  for (size_t k = 0; k < 2; ++k) in.lights.push_back({s.stars[k].position, s.stars[k].luminosity_lsun, &bake.tau_v[k]});
  in.camera = make_camera(s.camera);
  in.table = &table;
  RenderOptions o;
  o.backend = Backend::Cuda;
  RunReport report;
  double view = 0;
  const spectral::SpectralDiffuseLight light = spectral_diffuse_light(s, m, {&table, &table, &table}, bake, in.camera, o, report, &view);
  ASSERT_TRUE(light.on_device());
  in.diffuse = &light;
  const Image gpu = spectral::render_spectral(in, Backend::Cuda), cpu = spectral::render_spectral(in, Backend::Cpu);
  const double d = worst_of_peak(cpu, gpu);
  std::printf("  the device's light between voxels, CPU against CUDA march: %.3g of the peak\n", d);
  EXPECT_LT(d, 1e-4);
}

// The whole render on each backend: the fields' photons are the same on both
// (fixed-point sums), so the images agree far within the fields' noise.
TEST_F(SpectralSceneGpu, RenderAgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  const Scene s = scene();
  RenderOptions cpu_options, gpu_options;
  gpu_options.backend = Backend::Cuda;
  const RenderOutput cpu = render_scene(s, cpu_options), gpu = render_scene(s, gpu_options);
  ASSERT_TRUE(gpu.report.diffuse.done);
  const double d = worst_of_peak(cpu.image, gpu.image);
  std::printf("  spectral render with light between voxels, CPU against CUDA: %.3g of the peak; field noise %.3g\n", d,
              gpu.report.diffuse.noise.front());
  EXPECT_LT(d, 1e-3);
}

// Prepared once on the GPU (the depth bakes with their device copies, the
// fields), each of three views, the first again last, is the whole render of
// that view on the GPU.
TEST_F(SpectralSceneGpu, PreparedOnceEachViewIsTheWholeRender) {
  NEBULA_SKIP_WITHOUT_GPU();
  const Scene s = scene();
  RenderOptions o;
  o.backend = Backend::Cuda;
  const std::shared_ptr<const PreparedSpectral> prepared = prepare_spectral(s, o);
  CameraSettings moved = s.camera;
  moved.position = {2.5, -2, 1.6};
  for (const CameraSettings& camera : {s.camera, moved, s.camera}) {
    Scene whole = s;
    whole.camera = camera;
    const double d = worst_of_peak(render_prepared_spectral(*prepared, camera).image, render_scene(whole, o).image);
    std::printf("  a view of the prepared scene against its whole render, CUDA: %.3g of the peak\n", d);
    EXPECT_LT(d, 1e-5);
  }
}

// A preparation after an edit on the GPU keeps what the edit left unchanged
// (the depth bakes with their device copies, the fields left on the device):
// new filters keep all of it, a star's power its depth bakes; each image is
// the whole render of the edited scene on the GPU.
TEST_F(SpectralSceneGpu, APreparationKeepsWhatTheEditLeftUnchanged) {
  NEBULA_SKIP_WITHOUT_GPU();
  RenderOptions o;
  o.backend = Backend::Cuda;
  const std::string range = "spectral.range_um=[0.3, 1.0]";
  const Scene a = scene({range});
  const std::shared_ptr<const PreparedSpectral> first = prepare_spectral(a, o);
  const Scene filters = scene({range, "bands=[\"V\", \"sdss_g\"]", "dust.tables={V = \"smooth.h5\", sdss_g = \"smooth.h5\"}"});
  const Scene dimmer = scene({range, "stars.1.luminosity_lsun=3e4"});
  const std::shared_ptr<const PreparedSpectral> second = prepare_spectral(filters, o, first.get());
  const std::shared_ptr<const PreparedSpectral> third = prepare_spectral(dimmer, o, second.get());
  EXPECT_TRUE(second->report.spectral->basis_kept && second->report.bake.reused && second->report.diffuse.reused);
  EXPECT_TRUE(third->report.bake.reused);
  EXPECT_FALSE(third->report.diffuse.reused);
  for (const auto& [prepared, s] : {std::pair{second, &filters}, std::pair{third, &dimmer}, std::pair{first, &a}}) {
    const double d = worst_of_peak(render_prepared_spectral(*prepared, s->camera).image, render_scene(*s, o).image);
    std::printf("  a kept preparation's view against the whole render, CUDA: %.3g of the peak\n", d);
    EXPECT_LT(d, 1e-5);
  }
}

}  // namespace
}  // namespace nebula
