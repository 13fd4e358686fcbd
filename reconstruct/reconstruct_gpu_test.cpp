// Powell's reconstruction on the GPU (one block per column and band) against
// the CPU (one thread per column and band): the same function, powell_column.
// Float sums in a different order take the searches along slightly different
// paths, so the maps are compared through the errors they reach, not bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "axial/axial_renderer.h"
#include "core/test_support.h"
#include "reconstruct/projection.h"
#include "reconstruct/reconstruct.h"

namespace nebula {
namespace {

Image render_straight(const AxialMap& m, Backend backend) {
  AxialRenderInputs in;
  in.map = &m;
  for (int b = 0; b < 3; ++b) {
    AxialRenderBand band;
    band.name = std::string(1, "BVR"[b]);
    band.albedo = 0.0f;
    in.bands.push_back(band);
  }
  in.camera = straight_camera(m.nx, m.nr, m.texel);
  return render_axial(in, backend);
}

double relative(const std::vector<float>& a, const std::vector<float>& ref) {
  double d = 0, s = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    d += std::pow(double(a[i]) - ref[i], 2);
    s += std::pow(double(ref[i]), 2);
  }
  return std::sqrt(d / s);
}

TEST(ReconstructGpu, ProjectionMatchesTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  const int n = 96;
  const float step = 0.5f;
  const ColumnProjection cpu = build_projection(n, step, Backend::Cpu);
  const ColumnProjection gpu = build_projection(n, step, Backend::Cuda);
  // The same march; float contraction (FMA) on the device may move a sample
  // position across a ring edge. Such a sample moves its fraction (at most
  // one step, 0.5 texel) from one entry of a row to another; a ray crosses
  // each edge twice, so an entry changes by at most two steps. The row's
  // total (the chord through the whole cylinder) stays the same but for
  // rounding: 2 K eps_32 of it with K = 2 n / step samples.
  const double k = 2.0 * n / step;
  int moved = 0;
  for (int j = 0; j < n; ++j) {
    double total_cpu = 0, total_gpu = 0;
    for (int i = 0; i < n; ++i) {
      const float d = std::fabs(gpu.at(j, i) - cpu.at(j, i));
      EXPECT_LE(d, 2.0f * step + 1e-5f) << "row " << j << " ring " << i;
      moved += d > 1e-5f;
      total_cpu += cpu.at(j, i);
      total_gpu += gpu.at(j, i);
    }
    EXPECT_NEAR(total_gpu, total_cpu, 2.0 * k * 0x1p-24 * total_cpu) << "row " << j;
  }
  EXPECT_LT(moved, n * n / 100);  // rare: under 1% of the entries (the axial GPU test's bound for pixels)
  std::printf("projection %d: %d of %d entries differ between GPU and CPU; relative difference %.3g\n", n, moved,
              n * n, relative(gpu.a, cpu.a));
}

TEST(ReconstructGpu, PowellOnTheGpuReachesTheCpusError) {
  NEBULA_SKIP_WITHOUT_GPU();
  AxialMap m = synthetic_axial_map("lopsided", 64, 48, 1.0f, 3);
  m.origin = {0, 0, 0};
  m.axis = {1, 0, 0};
  std::fill(m.tau_v.begin(), m.tau_v.end(), 0.0f);
  m.update_skip_structures();
  const Image image = render_straight(m, Backend::Cpu);
  ReconstructSettings s;
  s.method = ReconstructMethod::Powell;
  s.axis = {0.0, double(m.nr), 0.0};
  const StraightImage straight = straighten_image(image, s.axis);
  const ColumnProjection a = build_projection(m.nr, s.step_texels, Backend::Cpu);  // one matrix for both
  ReconstructReport cpu_report, gpu_report;
  s.backend = Backend::Cpu;
  const AxialMap cpu = reconstruct_axial_map(straight, s, a, &cpu_report);
  s.backend = Backend::Cuda;
  const AxialMap gpu = reconstruct_axial_map(straight, s, a, &gpu_report);
  double map_cpu = 0, map_gpu = 0, between = 0;
  for (int b = 0; b < 3; ++b) {
    map_cpu = std::max(map_cpu, relative(cpu.emission[size_t(b)], m.emission[size_t(b)]));
    map_gpu = std::max(map_gpu, relative(gpu.emission[size_t(b)], m.emission[size_t(b)]));
    between = std::max(between, relative(gpu.emission[size_t(b)], cpu.emission[size_t(b)]));
  }
  std::printf("Powell: image error CPU %.3g GPU %.3g; map error CPU %.3g GPU %.3g; GPU vs CPU maps %.3g; sweeps %lld / %lld\n",
              cpu_report.image_error, gpu_report.image_error, map_cpu, map_gpu, between, cpu_report.iterations,
              gpu_report.iterations);
  // The stated goal (docs/axial.md, image error below 1%) on both backends;
  // the maps are printed (the sums' order differs, so the searches do).
  EXPECT_LT(cpu_report.image_error, 1e-2);
  EXPECT_LT(gpu_report.image_error, 1e-2);
  EXPECT_GT(gpu_report.iterations, 0);
}

}  // namespace
}  // namespace nebula
