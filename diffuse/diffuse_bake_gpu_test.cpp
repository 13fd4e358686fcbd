// The bake on the GPU runs the same photons with the same fixed-point sums as
// the CPU; float contraction on the device can move a collision by an ulp and
// so, rarely, a photon's path: the fields agree far within their own noise.
#include <gtest/gtest.h>

#include <cmath>

#include "core/philox.h"
#include "core/test_support.h"
#include "diffuse/diffuse_bake.h"
#include "montecarlo/henyey_greenstein.h"

namespace nebula {
namespace {

// An n^3 cube over [-1, 1]^3 of random tau_v in [0, most).
DensityGrid random_cube(int n, float most, uint32_t seed) {
  DensityGrid grid;
  grid.shape.nx = grid.shape.ny = grid.shape.nz = n;
  grid.shape.voxel = 2.0f / n;
  grid.shape.origin = {-1, -1, -1};
  grid.tau_v.resize(grid.shape.count());
  for (size_t c = 0; c < grid.tau_v.size(); ++c) grid.tau_v[c] = most * philox_uniform4(seed, 0, uint32_t(c), 0, 0).u0;
  return grid;
}

// The optically thin table of Henyey-Greenstein dust (the response needs one).
ScatteringTable thin_table(double g) {
  ScatteringTable table = ScatteringTable::make_axes(4.0, 9, AngularBinning::UniformTheta, 72);
  for (int i = 0; i < table.n_tau(); ++i)
    for (int k = 0; k < table.n_mu(); ++k)
      table.P[table.index(i, k)] =
          static_cast<float>(table.tau[i] * hg_bin_mean(g, table.mu_edges[k], table.mu_edges[k + 1]));
  return table;
}

TEST(DiffuseBakeGpu, AgreesWithTheCpuWithinAFractionOfItsNoise) {
  NEBULA_SKIP_WITHOUT_GPU();
  const DensityGrid grid = random_cube(24, 0.3f, 9);
  const ScatteringTable table = thin_table(0.6);
  std::vector<DiffuseBand> bands(2);
  bands[0].name = "B";
  bands[0].extinction_ratio = 1.2f;
  bands[1].name = "V";
  for (DiffuseBand& b : bands) {
    b.albedo = 0.7f;
    b.g = 0.6f;
    b.table = &table;
  }
  const std::vector<StarLight> stars{{{0.1f, 0.05f, -0.2f}, {50.0f, 40.0f}}, {{3.0f, 0.0f, 0.5f}, {80.0f, 90.0f}}};
  for (int zonal : {0, 12}) {  // harmonics alone, then with both stars' zonal degrees
    DiffuseBakeOptions o;
    o.degree = zonal ? 3 : kMaxDiffuseDegree;
    o.zonal = zonal;
    o.cells = 12;
    o.photons = 200000;
    DiffuseBakeStats cpu_stats, gpu_stats;
    const DiffuseField cpu = bake_diffuse(grid, bands, stars, o, Backend::Cpu, &cpu_stats);
    const DiffuseField gpu = bake_diffuse(grid, bands, stars, o, Backend::Cuda, &gpu_stats);
    for (size_t b = 0; b < bands.size(); ++b) {
      const std::vector<float> c = cpu.band_coeffs(b), g = gpu.band_coeffs(b);
      ASSERT_EQ(c.size(), g.size());
      double diff = 0, norm = 0;
      size_t equal = 0;
      for (size_t i = 0; i < c.size(); ++i) {
        const double d = double(c[i]) - g[i];
        diff += d * d;
        norm += double(c[i]) * c[i];
        equal += c[i] == g[i];
      }
      const double rel = std::sqrt(diff / norm);
      std::printf("zonal %d, band %zu: CPU-GPU relative L2 difference %.3g (the field's noise %.3g), %.1f%% of coefficients equal\n",
                  zonal, b, rel, cpu_stats.noise[b], 100.0 * equal / c.size());
      EXPECT_LT(rel, 0.25 * cpu_stats.noise[b]) << "band " << b;
      EXPECT_NEAR(cpu_stats.noise[b], gpu_stats.noise[b], 0.1 * cpu_stats.noise[b]);
    }
    EXPECT_EQ(cpu_stats.photons, gpu_stats.photons);
  }
}

// A sweep's albedos from one pass: every slot's field on the GPU against the
// CPU's, and the largest albedo's slot equal to a bake of its own on the GPU.
TEST(DiffuseBakeGpu, SharedAlbedosAgreeWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  const DensityGrid grid = random_cube(20, 0.4f, 5);
  const ScatteringTable table = thin_table(0.3);
  auto bands = [&](float albedo) {
    std::vector<DiffuseBand> b(1);
    b[0].name = "V";
    b[0].albedo = albedo;
    b[0].g = 0.3f;
    b[0].table = &table;
    return b;
  };
  const std::vector<std::vector<DiffuseBand>> sets{bands(0.3f), bands(0.6f), bands(0.9f)};
  const std::vector<StarLight> stars{{{0.1f, 0.05f, -0.2f}, {50.0f}}};
  DiffuseBakeOptions o;
  o.cells = 10;
  o.photons = 200000;
  std::vector<DiffuseBakeStats> cpu_stats, gpu_stats;
  const std::vector<DiffuseField> cpu = bake_diffuse_shared(grid, sets, stars, o, Backend::Cpu, &cpu_stats);
  const std::vector<DiffuseField> gpu = bake_diffuse_shared(grid, sets, stars, o, Backend::Cuda, &gpu_stats);
  ASSERT_EQ(gpu.size(), sets.size());
  for (size_t s = 0; s < sets.size(); ++s) {
    const std::vector<float> c = cpu[s].band_coeffs(0), g = gpu[s].band_coeffs(0);
    ASSERT_EQ(c.size(), g.size());
    double diff = 0, norm = 0;
    for (size_t i = 0; i < c.size(); ++i) {
      diff += (double(c[i]) - g[i]) * (double(c[i]) - g[i]);
      norm += double(c[i]) * c[i];
    }
    const double rel = std::sqrt(diff / norm);
    std::printf("albedo %.1f: CPU-GPU relative L2 difference %.3g (the field's noise %.3g)\n", sets[s][0].albedo, rel,
                cpu_stats[s].noise[0]);
    EXPECT_LT(rel, 0.25 * cpu_stats[s].noise[0]) << "set " << s;
  }
  // The largest albedo's slot against the plain kernel on the GPU: the two
  // kernels are compiled apart, and float contraction may move a collision by
  // an ulp (as between CPU and GPU); the CPU's are equal bit for bit.
  const DiffuseField alone = bake_diffuse(grid, sets[2], stars, o, Backend::Cuda);
  const std::vector<float> a = alone.band_coeffs(0), b = gpu[2].band_coeffs(0);
  double diff = 0, norm = 0;
  size_t equal = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    diff += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    norm += double(a[i]) * a[i];
    equal += a[i] == b[i];
  }
  std::printf("albedo 0.9, shared slot against the plain GPU pass: relative L2 difference %.3g, %.1f%% equal\n",
              std::sqrt(diff / norm), 100.0 * equal / a.size());
  EXPECT_LT(std::sqrt(diff / norm), 0.25 * cpu_stats[2].noise[0]);
}

}  // namespace
}  // namespace nebula
