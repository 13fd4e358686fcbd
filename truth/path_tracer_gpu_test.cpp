// CPU and CUDA path tracers on one scene: the same samples (Philox keyed by
// pixel, sample and band), so images agree within their combined noise, and
// mostly far closer (they differ only where float arithmetic does).
#include <gtest/gtest.h>

#include <cstdio>

#include "core/philox.h"
#include "core/test_support.h"
#include "raycast/test_scenes.h"
#include "validation/image_compare.h"
#include "truth/truth_renderer.h"

namespace nebula {
namespace {

void expect_cpu_and_cuda_agree(bool equiangular) {
  NEBULA_SKIP_WITHOUT_GPU();
  DensityGrid g = testing::cube(24, 1.0f);
  for (size_t i = 0; i < g.tau_v.size(); ++i) {
    const float u = philox_uniform4(5, 0, uint32_t(i), 3, 0).u0;
    g.tau_v[i] = u < 0.3f ? 0.0f : 0.6f * u * u;
  }
  std::vector<float> j(g.tau_v.size(), 0.0f);
  for (size_t i = 0; i < j.size(); i += 7) j[i] = 0.01f;
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"B", 1.3f, 0.6f, 0.6f}, nullptr}, TruthBand{{"V", 1.0f, 0.9f, 0.3f}, &j}};
  // Stars outside the dust: a star inside it has heavy-tailed samples (docs/truth.md), which
  // would make the chi-square test below depend on a few paths.
  in.stars = {StarLight{{0.1f, 0.05f, 1.4f}, {1e3f, 8e2f}}, StarLight{{0, 3, 0}, {1e3f, 1e3f}}};
  CameraSettings cs;
  cs.position = {0.3f, -3.0f, 0.8f};
  cs.look_at = {0, 0, 0};
  cs.up = {0, 0, 1};
  cs.fov_deg = 50;
  cs.width = 64;
  cs.height = 48;
  in.camera = make_camera(cs);
  in.spp = 64;
  in.equiangular = equiangular;
  const TruthOutput cpu = render_truth_cpu(in), gpu = render_truth_cuda(in);
  const Comparison c = compare_images(gpu.image, cpu.image, &gpu.variance, &cpu.variance);
  for (const BandComparison& r : c.bands) {
    std::printf("%s band %s: rel L2 %.3g, noise %.3g, mean z^2 %.3g, beyond 4 sigma %.3g\n", equiangular ? "equiangular" : "collisions", r.band.c_str(), r.rel_l2,
                r.noise_rel_l2, r.mean_z2, r.beyond_4sigma);
    EXPECT_GT(r.signal_pixels, 1000u);
    EXPECT_TRUE(r.within_noise);
    EXPECT_NEAR(r.bias, 0.0, 4 * r.bias_stderr);
  }
  EXPECT_EQ(cpu.paths, gpu.paths);
  for (float v : gpu.image.pixels) EXPECT_TRUE(std::isfinite(v) && v >= 0);
  std::printf("vertices: cpu %llu, gpu %llu\n", (unsigned long long)cpu.counters.vertices,
              (unsigned long long)gpu.counters.vertices);
}

// A small image's pixels share their samples among several GPU threads: the
// same samples, so the image equals the one-thread-per-pixel launch's to the
// rounding of the double sums' order, whatever the number of shares.
TEST(TruthGpu, SharingAPixelsSamplesAmongThreadsChangesNoSample) {
  NEBULA_SKIP_WITHOUT_GPU();
  DensityGrid g = testing::cube(16, 1.0f);
  for (size_t i = 0; i < g.tau_v.size(); ++i) g.tau_v[i] = 0.4f * philox_uniform4(9, 0, uint32_t(i), 3, 0).u0;
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"B", 1.3f, 0.6f, 0.6f}, nullptr}, TruthBand{{"V", 1.0f, 0.9f, 0.3f}, nullptr}};
  in.stars = {StarLight{{0.05f, 0.02f, 0.01f}, {1e3f, 8e2f}}};
  in.camera = testing::telescope(24, 2.2f, 20);  // not square: a share kernel mixing x and y would show
  in.spp = 96;
  in.equiangular = true;
  in.gpu_threads_per_pixel = 1;
  const TruthOutput one = render_truth_cuda(in);
  double total = 0;
  for (float v : one.image.pixels) total += v;
  EXPECT_GT(total, 0.0);
  for (int shares : {7, 96, 0}) {  // uneven, one sample each, as many as fill the GPU
    in.gpu_threads_per_pixel = shares;
    const TruthOutput many = render_truth_cuda(in);
    ASSERT_EQ(many.image.pixels.size(), one.image.pixels.size());
    for (size_t i = 0; i < one.image.pixels.size(); ++i) {
      EXPECT_NEAR(many.image.pixels[i], one.image.pixels[i], 1e-5f * one.image.pixels[i]) << "shares " << shares;
      EXPECT_NEAR(many.variance.pixels[i], one.variance.pixels[i], 1e-4f * one.variance.pixels[i] + 1e-30f)
          << "shares " << shares;
    }
    EXPECT_EQ(many.paths, one.paths);
    EXPECT_EQ(many.counters.vertices, one.counters.vertices);
  }
}

TEST(TruthGpu, CpuAndCudaAgreeWithinTheirNoise) { expect_cpu_and_cuda_agree(false); }
TEST(TruthGpu, CpuAndCudaAgreeWithinTheirNoiseEquiangular) { expect_cpu_and_cuda_agree(true); }

}  // namespace
}  // namespace nebula
