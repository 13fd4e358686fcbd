// The axial marcher on the GPU: every skipping mode against the GPU's naive
// march, and the GPU against the CPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "axial/axial_diffuse.h"
#include "axial/axial_test_scenes.h"
#include "core/test_support.h"

namespace nebula {
namespace {

using testing::AxialScene;

struct Difference {
  double peak = 0, worst = 0, mean = 0, flipped = 0;  // flipped: fraction of pixels off by > 1e-4 peak
};

Difference compare(const Image& a, const Image& ref) {
  Difference d;
  for (size_t i = 0; i < ref.pixels.size(); ++i) {
    d.peak = std::max(d.peak, double(std::fabs(ref.pixels[i])));
    const double e = std::fabs(double(a.pixels[i]) - ref.pixels[i]);
    d.worst = std::max(d.worst, e);
    d.mean += e;
  }
  d.mean /= std::max<size_t>(1, ref.pixels.size());
  for (size_t i = 0; i < ref.pixels.size(); ++i)
    d.flipped += std::fabs(double(a.pixels[i]) - ref.pixels[i]) > 1e-4 * d.peak;
  d.flipped /= std::max<size_t>(1, ref.pixels.size());
  return d;
}

// On one backend the skipping modes take the same arithmetic path through
// the same non-empty samples as the naive march (one kernel, the mode a
// run-time argument), so they are expected to be bit-identical on the GPU
// too; the test allows 1e-6 of the peak and prints any difference.
// Against the CPU: float contraction (FMA) moves sample positions by ulps, so
// a sample within rounding of a texel boundary may read the neighbour texel,
// changing its pixel by up to one sample's contribution. Such flips are rare:
// at most 1% of the pixels may differ by more than 1e-4 of the peak, the mean
// difference must stay below 1e-4 of the peak and none may exceed 1/4 of it.
TEST(AxialRendererGpu, SkippingModesMatchNaiveAndTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  for (const std::string& name : synthetic_axial_map_names()) {
    AxialScene s(name, 96, 40);
    s.inputs.star_pixels = true;  // the star pixels' rays on both backends too
    for (int inc = 0; inc <= 90; inc += 15) {
      for (float distance : {0.0f, 6.0f}) {
        s.inputs.camera = s.view(inc, 64, distance);
        s.inputs.skip = AxialSkip::Naive;
        const Image naive = render_axial_cuda(s.inputs, nullptr);
        const Image cpu = render_axial_cpu(s.inputs, nullptr);
        const Difference c = compare(naive, cpu);
        if (inc % 45 == 0)
          std::printf("%s %d deg %s: GPU-CPU largest %.3g, mean %.3g of the peak %.3g; %.3g%% of pixels > 1e-4\n",
                      name.c_str(), inc, distance > 0 ? "perspective" : "orthographic",
                      c.peak > 0 ? c.worst / c.peak : 0.0, c.peak > 0 ? c.mean / c.peak : 0.0, c.peak,
                      100 * c.flipped);
        EXPECT_LE(c.flipped, 0.01) << name << " " << inc;
        EXPECT_LE(c.mean, 1e-4 * c.peak) << name << " " << inc;
        EXPECT_LE(c.worst, 0.25 * c.peak) << name << " " << inc;
        for (float v : naive.pixels) ASSERT_TRUE(std::isfinite(v));
        for (AxialSkip mode : {AxialSkip::Empty, AxialSkip::GlobalMax, AxialSkip::Omega, AxialSkip::OmegaMulti,
                               AxialSkip::Distance, AxialSkip::ThesisOmegaMax, AxialSkip::ThesisOmegaLarge,
                               AxialSkip::ThesisOmegaMulti}) {
          s.inputs.skip = mode;
          const Difference d = compare(render_axial_cuda(s.inputs, nullptr), naive);
          EXPECT_LE(d.worst, 1e-6 * d.peak) << name << " " << inc << " " << to_string(mode);
          if (d.worst > 0)
            std::printf("%s %d deg %s: not bit-identical (largest %.3g of the peak)\n", name.c_str(), inc,
                        to_string(mode), d.worst / d.peak);
        }
      }
    }
  }
}

// Deformations (axial_deform.h) on the GPU: the same noise and displacement
// map as the CPU (one NEBULA_HD function), so the deformed naive march follows
// the CPU's with the bounds above (a pull differing by float contraction may
// move a sample across a texel boundary, like a position does), for every
// noise kind as colour and as shape deformation, with a star; and on the GPU
// every skipping mode matches its naive march (1e-6 of the peak, printed when
// not bit-identical).
TEST(AxialRendererGpu, DeformedMarchMatchesTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  const NoiseKind kinds[] = {NoiseKind::Simplex, NoiseKind::Fbm, NoiseKind::Turbulence, NoiseKind::Cellular};
  for (const std::string& name : synthetic_axial_map_names()) {
    AxialScene s(name, 96, 40);
    s.inputs.star_pixels = true;  // the star pixels' rays on both backends too
    for (int k = 0; k < 4; ++k) {
      AxialDeformSettings& d = s.inputs.deform;
      d.colour = d.shape = true;
      d.colour_noise.kind = kinds[k];
      d.colour_noise.amplitude = 0.7f;
      d.shape_noise.kind = kinds[(k + 1) % 4];
      d.shape_noise.amplitude = 0.4f;
      d.shape_noise.seed = 3 + k;
      for (int inc : {0, 45, 90}) {
        for (float distance : {0.0f, 6.0f}) {
          s.inputs.camera = s.view(inc, 64, distance);
          s.inputs.skip = AxialSkip::Naive;
          const Image naive = render_axial_cuda(s.inputs, nullptr);
          const Image cpu = render_axial_cpu(s.inputs, nullptr);
          for (float v : naive.pixels) ASSERT_TRUE(std::isfinite(v));
          const Difference c = compare(naive, cpu);
          std::printf("%s, colour %s, shape %s, %d deg %s: GPU-CPU largest %.3g, mean %.3g of the peak %.3g; "
                      "%.3g%% of pixels > 1e-4\n",
                      name.c_str(), to_string(d.colour_noise.kind), to_string(d.shape_noise.kind), inc,
                      distance > 0 ? "perspective" : "orthographic", c.peak > 0 ? c.worst / c.peak : 0.0,
                      c.peak > 0 ? c.mean / c.peak : 0.0, c.peak, 100 * c.flipped);
          EXPECT_LE(c.flipped, 0.01) << name << " " << k << " " << inc;
          EXPECT_LE(c.mean, 1e-4 * c.peak) << name << " " << k << " " << inc;
          EXPECT_LE(c.worst, 0.25 * c.peak) << name << " " << k << " " << inc;
          for (AxialSkip mode : axial_skip_modes()) {
            if (mode == AxialSkip::Naive) continue;
            s.inputs.skip = mode;
            const Difference m = compare(render_axial_cuda(s.inputs, nullptr), naive);
            EXPECT_LE(m.worst, 1e-6 * m.peak) << name << " " << k << " " << inc << " " << to_string(mode);
            if (m.worst > 0)
              std::printf("%s %d deg deformed %s: not bit-identical (largest %.3g of the peak)\n", name.c_str(), inc,
                          to_string(mode), m.worst / m.peak);
          }
        }
      }
    }
  }
}

// The axial diffuse field baked on the GPU agrees with the CPU's within a
// fraction of its noise (the photons' paths differ by float contraction, as
// in diffuse_gpu_tests; the ring averages run on the host), and the march
// with it follows the CPU's with the bounds above, in the skipping modes.
// With zonal degrees (to 24 above degree 3) as without.
TEST(AxialRendererGpu, DiffuseFieldMatchesTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  for (const int zonal : {0, 24})
  for (const std::string name : {"cloud", "bipolar"}) {
    AxialScene s(name, 96, 40, normalize(Vec3{1, 2, 3}), 50.0f, 1.0f);
    s.inputs.star_pixels = true;  // the star pixels' rays on both backends too
    std::vector<DiffuseBand> bands;
    for (const auto& b : s.inputs.bands) {
      DiffuseBand d;
      static_cast<Band&>(d) = b;
      d.table = &s.table;
      bands.push_back(d);
    }
    DiffuseBakeOptions o;
    o.photons = 1u << 16;
    o.cells = 24;
    o.degree = 3;
    o.zonal = zonal;
    const StarLight star{s.inputs.stars[0].position, s.inputs.stars[0].power};
    AxialDiffuseStats cpu_stats;
    const DiffuseField cpu_field = bake_axial_diffuse(s.map, bands, {star}, o, Backend::Cpu, &cpu_stats);
    const DiffuseField gpu_field = bake_axial_diffuse(s.map, bands, {star}, o, Backend::Cuda);
    ASSERT_EQ(cpu_field.host_packed().size(), gpu_field.host_packed().size());
    double diff = 0, norm = 0;
    for (size_t i = 0; i < cpu_field.host_packed().size(); ++i) {
      diff += std::pow(double(cpu_field.host_packed()[i]) - gpu_field.host_packed()[i], 2);
      norm += std::pow(double(cpu_field.host_packed()[i]), 2);
    }
    const double rel = std::sqrt(diff / norm);
    std::printf("%s, zonal %d: axial field CPU-GPU relative L2 difference %.3g (one 3D cell's noise %.3g)\n",
                name.c_str(), zonal, rel, cpu_stats.bake.noise[1]);
    ASSERT_EQ(gpu_field.n_zonal(), zonal > 0 ? zonal - 3 : 0);
    EXPECT_LT(rel, 0.25 * cpu_stats.bake.noise[1]) << name;
    s.inputs.diffuse = &cpu_field;
    for (int inc : {30, 90}) {
      s.inputs.camera = s.view(inc, 64, 6.0f);
      s.inputs.skip = AxialSkip::Naive;
      const Image cpu = render_axial_cpu(s.inputs, nullptr);
      const Image naive = render_axial_cuda(s.inputs, nullptr);
      const Difference c = compare(naive, cpu);
      std::printf("%s %d deg with the diffuse field (zonal %d): GPU-CPU largest %.3g, mean %.3g of the peak; %.3g%% of "
                  "pixels > 1e-4\n",
                  name.c_str(), inc, zonal, c.worst / c.peak, c.mean / c.peak, 100 * c.flipped);
      EXPECT_LE(c.flipped, 0.01) << name << " " << inc;
      EXPECT_LE(c.mean, 1e-4 * c.peak) << name << " " << inc;
      EXPECT_LE(c.worst, 0.25 * c.peak) << name << " " << inc;
      for (AxialSkip mode : {AxialSkip::OmegaMulti, AxialSkip::Distance}) {
        s.inputs.skip = mode;
        const Difference d = compare(render_axial_cuda(s.inputs, nullptr), naive);
        EXPECT_LE(d.worst, 1e-6 * d.peak) << name << " " << inc << " " << to_string(mode);
      }
    }
  }
}

// The axial bake (the 3D bake on an nx x nr x 1 grid) on both backends, with
// illumination_gpu_tests' bound: each of the nx + nr texel boundaries a path
// crosses may move by 4 L 2^-24 (FMA contraction) and hand that much of the
// densest texel's depth to its neighbour, plus 1e-5 relative.
TEST(AxialRendererGpu, BakeAgreesWithTheCpu) {
  NEBULA_SKIP_WITHOUT_GPU();
  const AxialMap m = synthetic_axial_map("cloud", 128, 64, 0.01f, 0, 3.0f);
  float densest = 0;
  for (float v : m.tau_v) densest = std::max(densest, v);
  const std::vector<float> xs{0.2f, 0.64f, -0.1f};  // inside, at a texel edge, beyond the map's start
  const BakeResult cpu = bake_axial_star_depths(m.nx, m.nr, m.texel, m.tau_v, xs, Backend::Cpu);
  const BakeResult gpu = bake_axial_star_depths(m.nx, m.nr, m.texel, m.tau_v, xs, Backend::Cuda);
  ASSERT_EQ(gpu.tau_v.size(), xs.size());
  for (size_t s = 0; s < xs.size(); ++s) {
    double worst = 0;
    for (int ir = 0; ir < m.nr; ++ir)
      for (int ix = 0; ix < m.nx; ++ix) {
        const size_t i = m.index(ix, ir);
        const double L = std::hypot((ix + 0.5) * m.texel - xs[s], (ir + 0.5) * m.texel);
        const double bound = 1e-5 * cpu.tau_v[s][i] + (m.nx + m.nr) * 4 * L * 0x1p-24 / m.texel * densest + 1e-7;
        worst = std::max(worst, std::fabs(double(gpu.tau_v[s][i]) - cpu.tau_v[s][i]) / bound);
      }
    std::printf("star at x = %g: worst CPU-GPU difference %.3g of its bound\n", xs[s], worst);
    EXPECT_LE(worst, 1.0);
  }
}

}  // namespace
}  // namespace nebula
