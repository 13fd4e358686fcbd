// The path tracer against exact answers: tolerances are 4 standard errors
// (from the tracer's own variance image, or the sample variance) plus the
// stated discretisation bias, never tuned.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/dda.h"
#include "core/error.h"
#include "core/philox.h"
#include "montecarlo/henyey_greenstein.h"
#include "raycast/renderer.h"
#include "raycast/test_scenes.h"
#include "validation/image_compare.h"
#include "truth/truth_renderer.h"

namespace nebula {
namespace {

using testing::cube;
using testing::fill_sphere;

Camera telescope(int pixels, float width, Vec3 from = {0, 0, -10}, Vec3 to = {0, 0, 0}) {
  CameraSettings s;
  s.projection = Projection::Orthographic;
  s.position = from;
  s.look_at = to;
  s.up = {0, 1, 0};
  s.ortho_width = width;
  s.width = s.height = pixels;
  return make_camera(s);
}

DensityGrid noise_grid(int n, float half, float scale, uint64_t seed) {
  DensityGrid g = cube(n, half);
  for (size_t i = 0; i < g.tau_v.size(); ++i) {
    const float u = philox_uniform4(seed, 0, uint32_t(i), 7, 0).u0;
    g.tau_v[i] = u < 0.3f ? 0.0f : scale * u * u;  // sparse and high-contrast
  }
  return g;
}

struct Mean {
  double sum = 0, sum2 = 0;
  int n = 0;
  void add(double v) { sum += v, sum2 += v * v, ++n; }
  double mean() const { return sum / n; }
  double stderr_() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean()) / (n - 1)); }
};

TEST(MajorantGrid, BoundsEveryVoxelOfItsBlockAndBorder) {
  const DensityGrid g = noise_grid(13, 1.0f, 3.0f, 5);
  const MajorantGrid m = build_majorant_grid(g, 4);
  EXPECT_EQ(m.shape.nx, 4);
  for (int z = 0; z < 13; ++z)
    for (int y = 0; y < 13; ++y)
      for (int x = 0; x < 13; ++x) {
        const float v = g.tau_v[g.shape.index(x, y, z)];
        // The block holding the voxel, and the blocks whose border it is in.
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int bx = (x + dx) / 4, by = (y + dy) / 4, bz = (z + dz) / 4;
              if (x + dx < 0 || y + dy < 0 || z + dz < 0 || bx >= 4 || by >= 4 || bz >= 4) continue;
              const size_t b = m.shape.index(bx, by, bz);
              EXPECT_LE(v, m.max_tau_v[b]);
              EXPECT_GE(v, m.min_tau_v[b]);
            }
      }
  EXPECT_THROW(build_majorant_grid(g, 0), Error);
}

// Transmittance by residual ratio tracking is unbiased, and exact in uniform blocks.
TEST(PathTracer, RatioTrackingTransmittanceIsUnbiased) {
  DensityGrid g = noise_grid(16, 1.0f, 0.8f, 11);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.3f, 0.5f, 0.0f}, nullptr}};
  in.camera = telescope(4, 1.0f);
  const HostPathScene h = prepare_path_scene(in);
  const float scale = 1.3f / g.shape.voxel;
  const Vec3 a{-0.93f, -0.71f, -1.5f}, b{0.87f, 0.52f, 1.6f};
  const double exact = std::exp(-1.3 * segment_optical_depth(g.view(), a, b));
  Mean m;
  PathCounters c;
  for (uint32_t i = 0; i < 40000; ++i) {
    PathRng rng(3, i, 0, 0);
    m.add(ratio_track(medium_of(h.scene), scale, a, b, rng, c.tentative));
  }
  std::printf("ratio tracking: %.6f +- %.6f, exact %.6f\n", m.mean(), m.stderr_(), exact);
  EXPECT_NEAR(m.mean(), exact, 4 * m.stderr_() + 1e-5);

  DensityGrid u = cube(16, 1.0f, 0.3f);
  in.density = &u;
  const HostPathScene hu = prepare_path_scene(in);
  PathRng rng(3, 0, 0, 0);
  const double uniform = ratio_track(medium_of(hu.scene), scale, a, b, rng, c.tentative);
  EXPECT_NEAR(uniform, std::exp(-1.3 * segment_optical_depth(u.view(), a, b)), 2e-5 * uniform);
}

// Delta tracking collides before leaving the grid with probability 1 - T.
TEST(PathTracer, DeltaTrackingCollidesWithProbabilityOneMinusT) {
  DensityGrid g = noise_grid(16, 1.0f, 0.8f, 12);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 0.9f, 0.5f, 0.0f}, nullptr}};
  in.camera = telescope(4, 1.0f);
  const HostPathScene h = prepare_path_scene(in);
  const Vec3 a{0.91f, -0.73f, -1.5f}, dir = normalize(Vec3{-0.9f, 0.55f, 1.7f});
  const double p = 1 - std::exp(-0.9 * segment_optical_depth(g.view(), a, a + 10.0f * dir));
  Mean m;
  PathCounters c;
  for (uint32_t i = 0; i < 40000; ++i) {
    PathRng rng(4, i, 0, 0);
    Vec3 hit;
    m.add(delta_track(medium_of(h.scene), 0.9f / g.shape.voxel, a, dir, rng, hit, c.tentative) ? 1.0 : 0.0);
  }
  EXPECT_NEAR(m.mean(), p, 4 * std::sqrt(p * (1 - p) / m.n));
}

// Pure extinction: an emitting layer seen through an absorbing slab gives
// j exp(-tau_b) per band, exactly and without noise (a = 0: no collisions
// are sampled, the emission integral is exact).
TEST(PathTracer, PureExtinctionSlabIsExactAndNoiseless) {
  DensityGrid g;
  g.shape.nx = g.shape.ny = 4;
  g.shape.nz = 6;
  g.shape.voxel = 1.0f;
  g.shape.origin = {-2, -2, 0};
  g.tau_v.assign(g.shape.count(), 0.0f);
  std::vector<float> j_b(g.shape.count(), 0.0f), j_v(g.shape.count(), 0.0f);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      g.tau_v[g.shape.index(x, y, 0)] = g.tau_v[g.shape.index(x, y, 1)] = 0.7f;
      j_b[g.shape.index(x, y, 4)] = 3.0f;
      j_v[g.shape.index(x, y, 4)] = 2.0f;
    }
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"B", 1.3f, 0.0f, 0.6f}, &j_b}, TruthBand{{"V", 1.0f, 0.0f, 0.6f}, &j_v}};
  in.stars = {StarLight{{0, 0, 10}, {1e3f, 1e3f}}};  // behind the layer: a = 0, it lights nothing
  in.camera = telescope(4, 3.0f, {0, 0, -10}, {0, 0, 3});
  in.spp = 4;
  const TruthOutput out = render_truth_cpu(in);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      EXPECT_NEAR(out.image.at(0, x, y), 3.0 * std::exp(-1.4 * 1.3), 1e-5);
      EXPECT_NEAR(out.image.at(1, x, y), 2.0 * std::exp(-1.4), 1e-5);
      EXPECT_LE(out.variance.at(0, x, y), 1e-12f);
      EXPECT_LE(out.variance.at(1, x, y), 1e-12f);
    }
  EXPECT_EQ(out.counters.vertices, 0u);
}

// Single scattering (orders limited to 1) in an optically thin uniform
// sphere around its star, seen from afar along +z, against the line integral
// I(b) = int sigma_s Phi / (4 pi r^2) p_HG(-z / r) exp(-k (z + zmax)) exp(-k r) dz
// of the continuous sphere (extinction included: the star sits at the centre,
// so its light crosses r of dust). Tolerance per annulus: 4 standard errors
// from the variance image plus the voxelisation bias. The staircase surface
// moves each end of the chord by up to half a voxel diagonal, sqrt(3) l / 2,
// adding or removing that much path where the integrand is f(b, -zmax) or
// f(b, zmax), and changes each of the two attenuating paths by up to sqrt(3) l
// (k sqrt(3) l relative each). Nothing else is approximated: the tracer
// evaluates 1/r^2 and the angle where it collides.
void expect_thin_sphere_profile(bool equiangular) {
  const int n = 64, pixels = 48, spp = 512;
  const float half = 1.0f, radius = 0.8f, kappa = 0.1f, albedo = 0.6f, g = 0.6f, power = 1000.0f;
  DensityGrid grid = cube(n, half);
  const float l = grid.shape.voxel;
  fill_sphere(grid, radius, kappa * l);
  TruthInputs in;
  in.density = &grid;
  in.bands = {TruthBand{{"V", 1.0f, albedo, g}, nullptr}};
  in.stars = {StarLight{{0, 0, 0}, {power}}};
  in.camera = telescope(pixels, 2.0f);
  in.spp = spp;
  in.max_orders = 1;
  in.equiangular = equiangular;
  const TruthOutput out = render_truth_cpu(in);
  const double sigma_s = albedo * kappa;
  // The integrand at impact parameter b and depth z.
  auto f = [&](double b, double z) {
    const double zmax = std::sqrt(radius * radius - b * b), r = std::hypot(b, z);
    // The camera looks along +z: light leaves towards -z, mu = -z / r.
    return sigma_s * power / (4 * kPiD * r * r) * hg_phase_double(g, -z / r) * std::exp(-kappa * (z + zmax)) *
           std::exp(-kappa * r);
  };
  auto reference = [&](double b) {
    const double zmax = std::sqrt(radius * radius - b * b);
    const int steps = 4000;
    double sum = 0;
    for (int k = 0; k < steps; ++k) sum += f(b, -zmax + (k + 0.5) * 2 * zmax / steps);
    return sum * 2 * zmax / steps;
  };
  auto rim_bias = [&](double b) {
    const double zmax = std::sqrt(radius * radius - b * b);
    return std::sqrt(3.0) / 2 * l * (f(b, -zmax) + f(b, zmax)) + reference(b) * 2 * kappa * std::sqrt(3.0) * l;
  };
  int checked = 0;
  for (int annulus = 0; annulus < 6; ++annulus) {
    const double b0 = 0.15 + 0.1 * annulus;
    double got = 0, expected = 0, var = 0, bias = 0;
    int count = 0;
    for (int y = 0; y < pixels; ++y)
      for (int x = 0; x < pixels; ++x) {
        Vec3 o, d;
        in.camera.ray(x, y, o, d);
        const double b = std::hypot(o.x, o.y);
        if (b < b0 || b >= b0 + 0.1) continue;
        got += out.image.at(0, x, y);
        var += out.variance.at(0, x, y);
        expected += reference(b);
        bias += rim_bias(b);
        ++count;
      }
    ASSERT_GT(count, 20);
    got /= count;
    expected /= count;
    bias /= count;
    const double se = std::sqrt(var) / count;
    std::printf("%s b in [%.2f, %.2f): truth %.5g +- %.2g, line integral %.5g, bias bound %.2g\n",
                equiangular ? "equiangular" : "collisions", b0, b0 + 0.1, got, se, expected, bias);
    EXPECT_NEAR(got, expected, 4 * se + bias);
    ++checked;
  }
  EXPECT_EQ(checked, 6);
  EXPECT_EQ(out.counters.capped, 0u);
}

TEST(PathTracer, ThinSphereSingleScatteringProfile) { expect_thin_sphere_profile(false); }
TEST(PathTracer, ThinSphereSingleScatteringProfileEquiangular) { expect_thin_sphere_profile(true); }

// Next-event estimation with and without equiangular samples (MIS): the same
// image within the combined noise, all orders, a star inside the dust; and
// equiangular sampling is the less noisy of the two there.
TEST(PathTracer, EquiangularMisAgreesAndHelpsWithAStarInDust) {
  DensityGrid g = noise_grid(12, 1.0f, 0.5f, 71);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.8f, 0.6f}, nullptr}};
  in.stars = {StarLight{{0.05f, 0.1f, -0.02f}, {100.0f}}, StarLight{{0.0f, 3.0f, 0.0f}, {100.0f}}};
  in.camera = telescope(16, 2.0f);
  in.spp = 64;
  const TruthOutput plain = render_truth_cpu(in);
  in.equiangular = true;
  in.seed = 9;
  const TruthOutput mis = render_truth_cpu(in);
  const BandComparison c = compare_images(mis.image, plain.image, &mis.variance, &plain.variance).bands[0];
  double var_plain = 0, var_mis = 0;
  for (size_t i = 0; i < plain.variance.pixels.size(); ++i) {
    var_plain += plain.variance.pixels[i];
    var_mis += mis.variance.pixels[i];
  }
  std::printf("equiangular vs collisions: bias %+.4f +- %.4f, mean z^2 %.3f; summed variance %.3g vs %.3g\n", c.bias,
              c.bias_stderr, c.mean_z2, var_mis, var_plain);
  EXPECT_NEAR(c.bias, 0.0, 4 * c.bias_stderr);
  EXPECT_LT(var_mis, var_plain);
}

// The integral of 1 / rho over [0, X] x [0, Y] from the corner (0, 0):
// X asinh(Y / X) + Y asinh(X / Y), by integrating first along y.
double corner_integral(double X, double Y) {
  if (X <= 0 || Y <= 0) return 0.0;
  return X * std::asinh(Y / X) + Y * std::asinh(X / Y);
}

// A stratum holding a star's image draws its points with density 1 / (Z rho)
// about the image: every point lies in the square, weight x (1 / rho) is the
// square's mean of 1 / rho for every sample (the four rectangles' closed form
// around the apex, an independent formula), and the weights estimate 1 and the
// mean of a smooth function within 4 sigma. Apexes inside, on an edge and at
// a corner (a star on four pixels' common corner).
TEST(PathTracer, StratumAboutAStarsImageCancelsOneOverRho) {
  const float x0 = 3.25f, y0 = 7.5f, h = 0.25f;
  const float apexes[][2] = {{3.3f, 7.61f}, {3.375f, 7.625f}, {3.25f, 7.56f}, {3.5f, 7.75f}, {3.25f, 7.5f}};
  for (const auto& a : apexes) {
    const double px = a[0], py = a[1];
    const double mean_inv_rho = (corner_integral(x0 + h - px, y0 + h - py) + corner_integral(px - x0, y0 + h - py) +
                                 corner_integral(x0 + h - px, py - y0) + corner_integral(px - x0, py - y0)) /
                                (double(h) * h);
    Mean w, smooth;
    double worst = 0;
    for (uint32_t i = 0; i < 200000; ++i) {
      const Uniform4 u = philox_uniform4(5, i, 0, 3, 0);
      const StratumPoint p = sample_stratum_about(x0, y0, h, a[0], a[1], u.u0, u.u1, u.u2);
      ASSERT_GE(p.x, x0);
      ASSERT_LE(p.x, x0 + h);
      ASSERT_GE(p.y, y0);
      ASSERT_LE(p.y, y0 + h);
      ASSERT_TRUE(std::isfinite(p.weight));
      const double rho = std::hypot(double(p.x) - px, double(p.y) - py);
      // (Checked a hundredth of the side away: the point's float coordinates
      // near 7 carry 5e-7 of rounding, a relative error of rho's below that.)
      if (rho > 1e-2 * h) worst = std::max(worst, std::fabs(p.weight / rho / mean_inv_rho - 1.0));
      w.add(p.weight);
      const double dx = (p.x - x0) / h, dy = (p.y - y0) / h;
      smooth.add(p.weight * (dx * dx + 2.0 * dy));  // square's mean 1/3 + 1
    }
    EXPECT_LT(worst, 1e-3) << "apex " << px << "," << py;
    EXPECT_NEAR(w.mean(), 1.0, 4 * w.stderr_()) << "apex " << px << "," << py;
    EXPECT_NEAR(smooth.mean(), 4.0 / 3.0, 4 * smooth.stderr_()) << "apex " << px << "," << py;
  }
}

// A pixel holding a star's image inside dust, with pixel-area strata: drawing
// the strata at the star about its image estimates the same mean as drawing
// them uniformly (within 4 sigma of both), with less variance: the uniform
// draw's rays pass at any impact parameter b and carry light ~ 1/b. A star
// inside one stratum, and one on four pixels' common corner (the image's
// centre), where rounding leaves it just outside some of the strata touching it.
TEST(PathTracer, StarStratumAgreesWithUniformStrataAndIsLessNoisy) {
  DensityGrid g = cube(8, 1.0f);
  for (float& t : g.tau_v) t = 0.2f;
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.6f, 0.75f}, nullptr}};
  in.camera = telescope(16, 2.0f);
  in.spp = 8192;
  in.pixel_side = 2;
  in.equiangular = true;
  // 16 pixels across 2 units: the first star appears 0.24 and 0.16 pixels
  // from the image's centre, inside one stratum of a pixel there.
  for (const Vec3 star : {Vec3{0.03f, 0.02f, 0.1f}, Vec3{0.0f, 0.0f, 0.1f}}) {
    in.stars = {StarLight{star, {100.0f}}};
    const std::optional<ImagePoint> at = project_point(in.camera, star);
    ASSERT_TRUE(at);
    const int px = std::min(int(at->x), 15), py = std::min(int(at->y), 15);
    float mean[2][kMaxBands], var[2][kMaxBands];
    for (int k = 0; k < 2; ++k) {
      in.star_strata = k == 0;
      const HostPathScene h = prepare_path_scene(in);
      ASSERT_TRUE(h.scene.stars[0].in_image);
      PathCounters c;
      trace_pixel(h.scene, in.camera, 1.0f, px, py, in.spp, mean[k], var[k], c);
    }
    std::printf("star at (%.6f, %.6f), pixel %d,%d: about the image %.5g +- %.3g, uniform %.5g +- %.3g\n", at->x,
                at->y, px, py, mean[0][0], std::sqrt(var[0][0]), mean[1][0], std::sqrt(var[1][0]));
    EXPECT_GT(mean[0][0], 0.0f);
    EXPECT_NEAR(mean[0][0], mean[1][0], 4 * std::sqrt(var[0][0] + var[1][0]));
    EXPECT_LT(var[0][0], var[1][0]);
  }
}

// van de Hulst's slab (a = 0.9, g = 0.75, tau = 2; the tabulator's reference
// case) through the renderer's own geometry: a 128 x 128 x 8 voxel slab,
// tau_v = 0.25 per voxel, lit by a star 1e6 voxels above it (irradiance 1 at
// the top face, uniform over the slab to 2e-5, direction within 1e-4 rad of the
// normal). Radiance leaving the centre of a face, sampled over cosine-weighted
// exit directions, integrates to the flux: R = pi E[L] / E_0, and T adds the
// unscattered exp(-tau) measured by the tracer's ratio tracking. The slab is
// 32 mean free paths wide: light reaching its edge from the centre (lateral
// flights of 16 mean free paths, probability ~e^-16) is far below the noise.
TEST(PathTracer, VanDeHulstSlabThroughTheGrid) {
  DensityGrid g;
  g.shape.nx = g.shape.ny = 128;
  g.shape.nz = 8;
  g.shape.voxel = 1.0f;
  g.shape.origin = {-64, -64, 0};
  g.tau_v.assign(g.shape.count(), 0.25f);
  const float D = 1e6f;
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.9f, 0.75f}, nullptr}};
  in.stars = {StarLight{{0, 0, 8 + D}, {float(4 * kPiD * double(D) * D)}}};
  in.camera = telescope(4, 1.0f);
  const HostPathScene h = prepare_path_scene(in);
  const int n = 200000;
  auto flux = [&](float z, float up) {
    Mean m;
    PathCounters c;
    for (int i = 0; i < n; ++i) {
      const Uniform4 u = philox_uniform4(21, 0, uint32_t(i), up > 0 ? 1u : 2u, 0);
      const float cos_t = std::sqrt(u.u0), sin_t = std::sqrt(1 - u.u0);
      const Vec3 dir{sin_t * std::cos(2 * kPi * u.u1), sin_t * std::sin(2 * kPi * u.u1), up * cos_t};
      PathRng rng(22, uint32_t(i), up > 0 ? 1u : 2u, 0);
      m.add(kPiD * trace_path(h.scene, 0, Vec3{0, 0, z}, dir, rng, c));
    }
    EXPECT_EQ(c.capped, 0u);
    return m;
  };
  const Mean R = flux(8.0f, -1.0f);  // on the top face, looking down into the slab
  const Mean Td = flux(0.0f, 1.0f);  // on the bottom face, looking up
  PathCounters c;
  PathRng rng(23, 0, 0, 0);
  const double direct = ratio_track(medium_of(h.scene), 1.0f, Vec3{0, 0, 0}, Vec3{0, 0, 8}, rng, c.tentative);
  std::printf("slab: R = %.5f +- %.5f (0.09739), T = %.5f +- %.5f (0.66096), direct %.6f\n", R.mean(), R.stderr_(),
              Td.mean() + direct, Td.stderr_(), direct);
  EXPECT_NEAR(direct, std::exp(-2.0), 1e-6);
  EXPECT_NEAR(R.mean(), 0.09739, 4 * R.stderr_() + 1e-5);
  EXPECT_NEAR(Td.mean() + direct, 0.66096, 4 * Td.stderr_() + 1e-5);
}

// Chandrasekhar's semi-infinite, isotropically scattering medium (a = 0.8,
// normal incidence): R = 1 - H(1) sqrt(1 - a) = 0.28525, the tabulator's
// other reference case, through the grid as above. 40 voxels of tau_v = 1
// stand for "semi-infinite": the light that would come back from below 40 mean
// free paths is far below the noise (the diffuse light decays by
// exp(-sqrt(3 (1 - a)) tau) = e^-31 there). Exercises the isotropic sampling
// branch and high scattering orders with Russian roulette.
TEST(PathTracer, SemiInfiniteIsotropicReflectanceThroughTheGrid) {
  DensityGrid g;
  g.shape.nx = g.shape.ny = 128;
  g.shape.nz = 40;
  g.shape.voxel = 1.0f;
  g.shape.origin = {-64, -64, 0};
  g.tau_v.assign(g.shape.count(), 1.0f);
  const float D = 1e6f;
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.8f, 0.0f}, nullptr}};
  in.stars = {StarLight{{0, 0, 40 + D}, {float(4 * kPiD * double(D) * D)}}};
  in.camera = telescope(4, 1.0f);
  const HostPathScene h = prepare_path_scene(in);
  Mean R;
  PathCounters c;
  for (int i = 0; i < 100000; ++i) {
    const Uniform4 u = philox_uniform4(31, 0, uint32_t(i), 3, 0);
    const float cos_t = std::sqrt(u.u0), sin_t = std::sqrt(1 - u.u0);
    const Vec3 dir{sin_t * std::cos(2 * kPi * u.u1), sin_t * std::sin(2 * kPi * u.u1), -cos_t};
    PathRng rng(32, uint32_t(i), 3, 0);
    R.add(kPiD * trace_path(h.scene, 0, Vec3{0, 0, 40}, dir, rng, c));
  }
  std::printf("semi-infinite a=0.8 g=0: R = %.5f +- %.5f (0.28525), %.2f collisions per path\n", R.mean(),
              R.stderr_(), double(c.vertices) / R.n);
  EXPECT_EQ(c.capped, 0u);
  EXPECT_NEAR(R.mean(), 0.28525, 4 * R.stderr_() + 1e-5);
}

// In the optically thin limit the fast renderer (thin table, exact
// traversal) and the path tracer with single scattering compute the same
// quantity; their image sums agree within 4 standard errors of the truth plus
// the fast renderer's stated approximations: it holds the source at the voxel
// centre (second order, (l / d)^2 with the star d >= 3 grid widths away, < 1e-3) and
// does not attenuate inside a voxel (camera side and star side: up to
// 2 x max tau per voxel, 2e-2 here, relative).
TEST(PathTracer, AgreesWithTheFastRendererInTheThinLimit) {
  const int n = 12, pixels = 24;
  testing::OneStarScene s;
  s.grid = noise_grid(n, 1.0f, 0.01f, 31);
  s.table = testing::thin_table(0.0, 180, 2.0);
  const Vec3 star{0.3f, 6.0f, -1.0f};
  const float power = 1e4f;
  s.finish(star, power, 0.6f, telescope(pixels, 2.0f, {0, 0, -10}, {0, 0, 0}));
  const Image fast = render_cpu(s.inputs, nullptr);
  TruthInputs in;
  in.density = &s.grid;
  in.bands = {TruthBand{{"V", 1.0f, 0.6f, 0.0f}, nullptr}};
  in.stars = {StarLight{star, {power}}};
  in.camera = s.inputs.camera;
  in.spp = 1024;
  in.max_orders = 1;
  const TruthOutput out = render_truth_cpu(in);
  double sum_fast = 0, sum_truth = 0, var = 0;
  for (int y = 0; y < pixels; ++y)
    for (int x = 0; x < pixels; ++x) {
      sum_fast += fast.at(0, x, y);
      sum_truth += out.image.at(0, x, y);
      var += out.variance.at(0, x, y);
    }
  const double se = std::sqrt(var);
  const double bias = sum_fast * (2 * 0.01 + 1e-3);
  std::printf("thin limit: fast %.6g, truth %.6g +- %.2g (bias bound %.2g)\n", sum_fast, sum_truth, se, bias);
  EXPECT_NEAR(sum_truth, sum_fast, 4 * se + bias);
  EXPECT_LT(4 * se, 0.05 * sum_fast);  // the test has teeth
}

// Next-event transmittance by ratio tracking or by the exact voxel sum: two
// unbiased estimators of one image, equal within their combined noise.
TEST(PathTracer, ExactAndRatioTrackedTransmittanceAgree) {
  DensityGrid g = noise_grid(12, 1.0f, 1.0f, 51);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.8f, 0.5f}, nullptr}};
  in.stars = {StarLight{{0.1f, 1.5f, 0.2f}, {100.0f}}};
  in.camera = telescope(16, 2.0f);
  in.spp = 64;
  const TruthOutput ratio = render_truth_cpu(in);
  in.exact_transmittance = true;
  in.seed = 7;
  const TruthOutput exact = render_truth_cpu(in);
  const BandComparison c = compare_images(ratio.image, exact.image, &ratio.variance, &exact.variance).bands[0];
  std::printf("ratio vs exact transmittance: bias %+.4f +- %.4f, mean z^2 %.3f over %zu pixels\n", c.bias,
              c.bias_stderr, c.mean_z2, c.signal_pixels);
  EXPECT_GT(c.signal_pixels, 100u);
  EXPECT_NEAR(c.bias, 0.0, 4 * c.bias_stderr);
  EXPECT_TRUE(c.within_noise);
}

TEST(PathTracer, SameSeedSameImageAndNoNaN) {
  DensityGrid g = noise_grid(10, 1.0f, 2.0f, 41);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"B", 1.3f, 0.7f, 0.8f}, nullptr}, TruthBand{{"V", 1.0f, 0.99f, -0.5f}, nullptr}};
  in.stars = {StarLight{{0.05f, 0.02f, 0.01f}, {100.0f, 80.0f}}, StarLight{{3, 0, 0}, {10.0f, 10.0f}}};
  in.camera = telescope(12, 2.2f);
  in.spp = 8;
  const TruthOutput a = render_truth_cpu(in), b = render_truth_cpu(in);
  EXPECT_EQ(a.image.pixels, b.image.pixels);
  EXPECT_EQ(a.variance.pixels, b.variance.pixels);
  for (float v : a.image.pixels) EXPECT_TRUE(std::isfinite(v) && v >= 0);
  for (float v : a.variance.pixels) EXPECT_TRUE(std::isfinite(v) && v >= 0);
  EXPECT_GT(a.counters.vertices, 0u);
  in.seed = 2;
  EXPECT_NE(render_truth_cpu(in).image.pixels, a.image.pixels);
}

// A pixel's samples split into shares (as the GPU launch splits a small
// image's) are the same samples: the shares' sums add up to the whole range's,
// to the rounding of the double sums, with strata (pixel-area sampling) too.
TEST(PathTracer, SplittingAPixelsSamplesKeepsEverySample) {
  DensityGrid g = noise_grid(10, 1.0f, 2.0f, 43);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"B", 1.3f, 0.7f, 0.8f}, nullptr}, TruthBand{{"V", 1.0f, 0.9f, 0.3f}, nullptr}};
  in.stars = {StarLight{{0.05f, 0.02f, 0.01f}, {100.0f, 80.0f}}};
  in.camera = telescope(6, 2.2f);
  in.spp = 36;
  in.equiangular = true;
  for (int side : {1, 3}) {
    in.pixel_side = side;
    const HostPathScene h = prepare_path_scene(in);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 6; ++x) {
        PathCounters c;
        PixelSums whole, parts[3];
        trace_pixel_samples(h.scene, in.camera, x, y, 0, in.spp, whole, c);
        const int cut[4] = {0, 5, 22, in.spp};  // uneven shares
        for (int k = 0; k < 3; ++k) trace_pixel_samples(h.scene, in.camera, x, y, cut[k], cut[k + 1], parts[k], c);
        for (int b = 0; b < 2; ++b) {
          const double sum = parts[0].sum[b] + parts[1].sum[b] + parts[2].sum[b];
          const double sum2 = parts[0].sum2[b] + parts[1].sum2[b] + parts[2].sum2[b];
          EXPECT_NEAR(sum, whole.sum[b], 1e-12 * std::fabs(whole.sum[b])) << "pixel " << x << "," << y;
          EXPECT_NEAR(sum2, whole.sum2[b], 1e-12 * std::fabs(whole.sum2[b])) << "pixel " << x << "," << y;
        }
        float mean[kMaxBands], var[kMaxBands], m2[kMaxBands], v2[kMaxBands];
        trace_pixel(h.scene, in.camera, in.exposure, x, y, in.spp, mean, var, c);
        pixel_moments(whole, 2, in.spp, in.exposure, m2, v2);
        for (int b = 0; b < 2; ++b) {
          EXPECT_EQ(mean[b], m2[b]);
          EXPECT_EQ(var[b], v2[b]);
        }
      }
    // Not a vacuous comparison: the pixels hold light.
    EXPECT_GT(render_truth_cpu(in).image.pixels[size_t(2 * 6 + 3)], 0.0f);
  }
}

// A camera inside the cloud (perspective and fisheye) next to a star inside
// dust: finite, non-negative pixels; the 1/r^2 of a collision near the star
// is a large but finite sample.
TEST(PathTracer, CameraInsideTheCloudStaysFinite) {
  DensityGrid g = noise_grid(10, 1.0f, 1.0f, 61);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.6f, 0.6f}, nullptr}};
  in.stars = {StarLight{{0.01f, 0.02f, 0.03f}, {1e4f}}};
  for (Projection p : {Projection::Perspective, Projection::Fisheye}) {
    CameraSettings cs;
    cs.projection = p;
    cs.position = {0.3f, -0.2f, 0.1f};
    cs.look_at = {0, 0, 0};
    cs.up = {0, 0, 1};
    cs.width = cs.height = 12;
    in.camera = make_camera(cs);
    in.spp = 8;
    const TruthOutput out = render_truth_cpu(in);
    double sum = 0;
    for (float v : out.image.pixels) {
      EXPECT_TRUE(std::isfinite(v) && v >= 0);
      sum += v;
    }
    for (float v : out.variance.pixels) EXPECT_TRUE(std::isfinite(v) && v >= 0);
    EXPECT_GT(sum, 0.0);
  }
}

TEST(PathTracer, RefusesBadInputs) {
  DensityGrid g = cube(4, 1.0f, 0.1f);
  TruthInputs in;
  in.density = &g;
  in.bands = {TruthBand{{"V", 1.0f, 0.6f, 0.6f}, nullptr}};
  in.camera = telescope(4, 1.0f);
  in.spp = 1;
  EXPECT_THROW(render_truth_cpu(in), Error);
  in.spp = 4;
  in.bands[0].g = 1.0f;
  EXPECT_THROW(render_truth_cpu(in), Error);
  in.bands[0].g = 0.0f;
  in.stars = {StarLight{{0, 0, 0}, {}}};
  EXPECT_THROW(render_truth_cpu(in), Error);
  std::vector<float> short_emission(3, 0.0f);
  in.stars.clear();
  in.bands[0].emission = &short_emission;
  EXPECT_THROW(render_truth_cpu(in), Error);
}

}  // namespace
}  // namespace nebula
