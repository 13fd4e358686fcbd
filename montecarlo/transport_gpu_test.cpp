// CPU and GPU compute the same function: the same photon streams, the same
// physics code, different launches. Run with `ctest -L gpu` on a CUDA machine.
#include <gtest/gtest.h>

#include <cmath>

#include "core/test_support.h"
#include "montecarlo/slab.h"
#include "montecarlo/tabulate.h"
#include "montecarlo/test_stats.h"

namespace nebula {
namespace {

TabulateParams gpu_params() {
  TabulateParams p;
  p.tau_max = 10;
  p.tau_bins = 41;
  p.mu_bins = 72;
  p.photons_per_row = 100000;
  return p;
}

TEST(Gpu, TableAgreesWithCpuWithinFourStandardErrors) {
  NEBULA_SKIP_WITHOUT_GPU();
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    TabulateParams p = gpu_params();
    p.binning = binning;
    const Tabulation cpu = tabulate(p, Backend::Cpu);
    const Tabulation gpu = tabulate(p, Backend::Cuda);
    double worst = 0;
    for (size_t e = 0; e < cpu.P.size(); ++e) {
      const double z = std::fabs(test::z_score(cpu.P[e], cpu.P_stderr[e], gpu.P[e], gpu.P_stderr[e]));
      worst = std::fmax(worst, z);
      EXPECT_LT(z, 4.0) << "entry " << e;
    }
    for (int i = 0; i < p.tau_bins; ++i) {
      EXPECT_LT(std::fabs(test::z_score(cpu.total[i], cpu.total_stderr[i], gpu.total[i],
                                        gpu.total_stderr[i])),
                4.0);
      EXPECT_NEAR(cpu.unscattered[i], gpu.unscattered[i], 1e-5);
    }
    // Same random streams: the two backends follow nearly the same photons.
    const double rel_events = std::fabs(double(cpu.scattering_events) - double(gpu.scattering_events)) /
                              double(cpu.scattering_events);
    EXPECT_LT(rel_events, 1e-3);
    std::printf("binning %s: largest |z| between CPU and GPU entries %.3f, events %llu vs %llu\n",
                to_string(binning), worst, (unsigned long long)cpu.scattering_events,
                (unsigned long long)gpu.scattering_events);
  }
}

TEST(Gpu, RunToRunIdentical) {
  NEBULA_SKIP_WITHOUT_GPU();
  const TabulateParams p = gpu_params();
  const Tabulation a = tabulate(p, Backend::Cuda);
  const Tabulation b = tabulate(p, Backend::Cuda);
  EXPECT_EQ(a.P, b.P);
  EXPECT_EQ(a.scattering_events, b.scattering_events);
}

TEST(Gpu, ConservesEnergyAtAlbedoOne) {
  NEBULA_SKIP_WITHOUT_GPU();
  TabulateParams p = gpu_params();
  p.albedo = 1.0;
  const Tabulation t = tabulate(p, Backend::Cuda);
  EXPECT_EQ(t.capped_photons, 0u);
  for (int i = 0; i < p.tau_bins; ++i) EXPECT_NEAR(t.total[i] + t.unscattered[i], 1.0, 1e-6);
}

TEST(Gpu, SlabMatchesVanDeHulstAndTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  SlabParams p;
  p.albedo = 0.9;
  p.g = 0.75;
  p.tau = 2.0;
  p.photons = 1 << 24;
  const SlabResult gpu = simulate_slab(p, Backend::Cuda);
  EXPECT_NEAR(gpu.R_diffuse, 0.09739, 4 * gpu.R_stderr);
  EXPECT_NEAR(gpu.T_total, 0.66096, 4 * gpu.T_stderr);
  p.photons = 1 << 20;
  const SlabResult a = simulate_slab(p, Backend::Cpu);
  const SlabResult b = simulate_slab(p, Backend::Cuda);
  EXPECT_LT(std::fabs(test::z_score(a.R_diffuse, a.R_stderr, b.R_diffuse, b.R_stderr)), 4.0);
  EXPECT_LT(std::fabs(test::z_score(a.T_total, a.T_stderr, b.T_total, b.T_stderr)), 4.0);
}

}  // namespace
}  // namespace nebula
