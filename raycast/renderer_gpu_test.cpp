#include <gtest/gtest.h>

#include <cmath>

#include "core/philox.h"
#include "core/test_support.h"
#include "diffuse/diffuse_bake.h"
#include "raycast/renderer.h"
#include "raycast/test_scenes.h"

namespace nebula {
namespace {

// The same march_ray on both backends; float contraction on the GPU moves
// voxel-boundary crossings by ulps, so images agree to 1e-4 of the peak.
TEST(RendererGpu, AgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  testing::OneStarScene s;
  s.grid = testing::noise_cube(48, 0.4f, 3);
  s.table = testing::thin_table(0.6, 72, 10.0);
  s.finish({0.1f, 0.2f, -0.1f}, 100.0f, 0.6f, testing::oblique_camera(96, 64));
  MarchMode preview;
  preview.voxel_sources = true;  // the viewer's preview (raycast/voxel_sources.h)
  for (MarchMode mode : {MarchMode{}, MarchMode{0.25f, true}, preview}) {
    s.inputs.mode = mode;
    RenderStats cpu_stats, gpu_stats;
    const Image cpu = render_cpu(s.inputs, &cpu_stats);
    const Image gpu = render_cuda(s.inputs, &gpu_stats);
    double peak = 0, worst = 0;
    for (size_t i = 0; i < cpu.pixels.size(); ++i) {
      peak = std::max(peak, double(cpu.pixels[i]));
      worst = std::max(worst, double(std::fabs(cpu.pixels[i] - gpu.pixels[i])));
    }
    double mean = 0;
    for (size_t i = 0; i < cpu.pixels.size(); ++i) mean += std::fabs(cpu.pixels[i] - gpu.pixels[i]);
    mean /= cpu.pixels.size();
    std::printf("%s: largest CPU-GPU difference %.3g of the peak %.3g, mean %.3g of it\n",
                mode.voxel_sources ? "preview" : mode.step_voxels > 0 ? "smooth" : "exact", worst / peak, peak, mean / peak);
    EXPECT_GT(peak, 0.0);
    if (mode.step_voxels == 0) {
      EXPECT_LT(worst, 1e-4 * peak);
    } else {
      // A smooth-mode sample within rounding of a voxel boundary may fall on
      // either side, seen through either voxel's entry transmittance: its
      // contribution (at most its pixel's value) changes by at most
      // 1 - exp(-tau_max A_max/A_V), here 1 - exp(-0.4). Such flips are rare,
      // so on average the backends must still agree to 1e-5 of the peak.
      const double flip = 1 - std::exp(-0.4);
      for (size_t i = 0; i < cpu.pixels.size(); ++i)
        EXPECT_LE(std::fabs(cpu.pixels[i] - gpu.pixels[i]), 1e-4 * peak + flip * cpu.pixels[i]);
      EXPECT_LT(mean, 1e-5 * peak);
    }
    EXPECT_EQ(cpu_stats.table_clamps, gpu_stats.table_clamps);
  }
}

// With a diffuse field: the same marcher on both backends (the field's lookups
// and the delta-M peak's transmittance included).
TEST(RendererGpu, DiffuseFieldAgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  testing::OneStarScene s;
  s.grid = testing::noise_cube(40, 0.4f, 11);
  s.table = testing::thin_table(0.6, 72, 10.0);
  s.finish({0.1f, 0.2f, -0.1f}, 100.0f, 0.6f, testing::oblique_camera(96, 64));
  DiffuseBand band;
  static_cast<Band&>(band) = s.inputs.bands[0];
  band.table = &s.table;
  for (int zonal : {0, 16}) {  // harmonics alone, then with the star's zonal degrees
    DiffuseBakeOptions o;
    o.degree = zonal ? 3 : kMaxDiffuseDegree;
    o.zonal = zonal;
    o.cells = 20;
    o.photons = 100000;
    const DiffuseField field = bake_diffuse(s.grid, {band}, {s.inputs.stars[0]}, o, Backend::Cpu);
    s.inputs.diffuse = &field;
    for (bool voxel_sources : {false, true}) {  // the exact march, then the viewer's preview
      s.inputs.mode.voxel_sources = voxel_sources;
      const Image cpu = render_cpu(s.inputs, nullptr);
      const Image gpu = render_cuda(s.inputs, nullptr);
      double peak = 0, worst = 0, mean = 0;
      for (size_t i = 0; i < cpu.pixels.size(); ++i) {
        peak = std::max(peak, double(cpu.pixels[i]));
        worst = std::max(worst, double(std::fabs(cpu.pixels[i] - gpu.pixels[i])));
        mean += std::fabs(cpu.pixels[i] - gpu.pixels[i]) / cpu.pixels.size();
      }
      std::printf("diffuse%s, zonal %d: largest CPU-GPU difference %.3g of the peak %.3g, mean %.3g of it\n",
                  voxel_sources ? ", preview" : "", zonal, worst / peak, peak, mean / peak);
      EXPECT_GT(peak, 0.0);
      EXPECT_LT(worst, 1e-4 * peak);
    }
  }
}

}  // namespace
}  // namespace nebula
