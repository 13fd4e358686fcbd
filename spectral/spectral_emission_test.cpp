// Emission in the spectral renderer (docs/spectral.md, "Emission"): lines
// and continua seen through the dust's spectral attenuation, every method.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "illumination/filters.h"
#include "spectral/spectral_test_scene.h"

namespace nebula::spectral {
namespace {

using testing::filters;

// A uniform cube of n voxels a side, tau_V t per voxel, seen face-on by an
// orthographic camera: every ray crosses n whole voxels, the k-th (from the
// eye) behind V-band depth k t.
struct UniformCube {
  DensityGrid grid;
  Camera camera;
  UniformCube(int n, float t) {
    grid.shape.nx = grid.shape.ny = grid.shape.nz = n;
    grid.shape.voxel = 1.0f / n;
    grid.shape.origin = {-0.5f, -0.5f, -0.5f};
    grid.tau_v.assign(grid.shape.count(), t);
    CameraSettings cs;
    cs.projection = Projection::Orthographic;
    cs.ortho_width = 0.6;  // well inside the cube's face
    cs.position = {0.0f, 0.0f, -3.0f};
    cs.look_at = {0, 0, 0};
    cs.up = {0, 1, 0};
    cs.width = cs.height = 4;
    camera = make_camera(cs);
  }
};

Image render_emission(const UniformCube& cube, const SpectralModel& m, std::vector<SpectralEmissionWeight> weights,
                      Backend backend = Backend::Cpu) {
  SpectralRenderInputs in;
  in.density = &cube.grid;
  in.model = &m;
  in.emission = std::move(weights);
  in.camera = cube.camera;
  return resolve_filters(render_spectral(in, backend), m);
}

// The exact answer through the cube for component c, weight w per voxel
// crossing: sum over the n voxels of w times the integral at depth k t.
double cube_answer(const SpectralModel& m, int filter, int c, int n, double t, double w) {
  double sum = 0.0;
  for (int k = 0; k < n; ++k) sum += w * emission_reference(m, filter, c, k * t);
  return sum;
}

double worst_against_cube(const Image& image, const SpectralModel& m, int c, int n, double t, double w) {
  double worst = 0.0;
  for (size_t f = 0; f < m.filter_names.size(); ++f) {
    const double want = cube_answer(m, int(f), c, n, t, w);
    if (!(want > 0.0)) continue;  // a line outside this filter
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        worst = std::max(worst, std::fabs(image.at(int(f), x, y) - want) / want);
  }
  return worst;
}

constexpr SpectralMethod kMethods[] = {SpectralMethod::Double,     SpectralMethod::Analytic,
                                       SpectralMethod::Projection, SpectralMethod::LightBasis,
                                       SpectralMethod::VoxelLight, SpectralMethod::Preintegrated};

// A line is a Dirac spike: every method takes it exactly, S_f(lambda_l)
// e^(-kappa_l D), so the cube's closed form holds to float rounding; here
// H-alpha (656.3 nm) in R and in a band around it, and a blue line in B.
TEST(SpectralEmission, LinesAreExactInEveryMethod) {
  const UniformCube cube(16, 0.1f);  // tau_V 1.6 across
  for (SpectralMethod method : kMethods) {
    SpectralSettings s;
    s.method = method;
    s.attenuation = method == SpectralMethod::Analytic ? Attenuation::Inverse : Attenuation::Law;
    const SpectralModel m = build_spectral_model(filters({"B", "R"}), {}, s, {{0.6563}, {0.4340}});
    ASSERT_EQ(m.n_emission_planes, 2);
    for (int c = 0; c < 2; ++c) {
      std::vector<SpectralEmissionWeight> w(2);
      w[size_t(1 - c)].scale = 0.0f;  // one line at a time
      w[size_t(c)].scale = 3.0f;      // weight 3 tau_V = 0.3 per voxel crossing
      const Image image = render_emission(cube, m, w);
      const double err = worst_against_cube(image, m, c, 16, 0.1, 0.3);
      std::printf("  method %d, line %d: largest error %.2e against the closed form\n", int(method), c, err);
      EXPECT_LT(err, 1e-5);
      // The other filter sees the line through its wing only (B at 656 nm: none).
      const double elsewhere = image.at(c == 0 ? 0 : 1, 1, 1);
      EXPECT_LE(elsewhere, 1e-3 * image.at(c == 0 ? 1 : 0, 1, 1));
    }
  }
}

// A continuum (a smooth emission spectrum rising to the red, as a quadratic
// in lambda, on 450-800 nm only) against the cube's exact sum of quadratures:
// the double integral and the closed form within their wavelength
// discretisation and cubic fits, the basis methods within their projection of
// e^(-kappa D) (the 1% per pixel of issue 14's goal).
TEST(SpectralEmission, ContinuumAgainstTheExactIntegral) {
  const UniformCube cube(16, 0.15f);  // tau_V 2.4 across
  const SpectralEmission continuum{0.0, {0.2, -0.4, 1.0}, 0.45, 0.80};
  for (SpectralMethod method : kMethods) {
    SpectralSettings s;
    s.method = method;
    s.wavelengths = 2000;
    s.attenuation = method == SpectralMethod::Analytic ? Attenuation::Inverse : Attenuation::Law;
    const SpectralModel m = build_spectral_model(filters({"B", "V", "R", "sdss_i"}), {}, s, {continuum});
    const Image image = render_emission(cube, m, {{nullptr, 2.0f}});
    const double err = worst_against_cube(image, m, 0, 16, 0.15, 0.3);
    std::printf("  method %d: largest pixel error %.2e against the exact integral\n", int(method), err);
    // Pre-integration: the continuum's own table, exact but for the grid's quadrature and the depth's interpolation.
    const bool exact = method == SpectralMethod::Double || method == SpectralMethod::Analytic ||
                       method == SpectralMethod::Preintegrated;
    EXPECT_LT(err, exact ? 2e-3 : 1e-2);
  }
}

// Emission from a weight grid and starlight in one image: the sum of the two
// rendered apart (the planes and the resolve's columns do not mix), for every
// method, on the noise cube with two stars.
TEST(SpectralEmission, AddsToTheStarlight) {
  auto scene = testing::noise_scene(12, 0.5f, {{0.1f, 0.2f, -0.1f}, {-0.2f, 0.0f, 0.2f}}, 20, 14);
  std::vector<float> weight(scene.grid.tau_v.size());
  for (size_t i = 0; i < weight.size(); ++i) weight[i] = 0.05f * float(i % 7);
  const std::vector<SpectralEmission> emission = {{0.6563}, {0.0, {1.0}, 0.0, 0.0}};
  for (SpectralMethod method : kMethods) {
    SpectralSettings s;
    s.method = method;
    s.attenuation = method == SpectralMethod::Analytic ? Attenuation::Inverse : Attenuation::Law;
    const auto f = filters({"B", "V", "R"});
    const SpectralModel both = build_spectral_model(f, {{41400}, {5770}}, s, emission);
    const SpectralModel stars = build_spectral_model(f, {{41400}, {5770}}, s);
    SpectralRenderInputs in = scene.inputs(both);
    in.emission = {{&weight, 1.0f}, {nullptr, 0.7f}};
    const Image sum = resolve_filters(render_spectral(in, Backend::Cpu), both);
    const Image star_light = resolve_filters(render_spectral(scene.inputs(stars), Backend::Cpu), stars);
    in.lights.clear();
    const SpectralModel glow = build_spectral_model(f, {}, s, emission);
    in.model = &glow;
    const Image emitted = resolve_filters(render_spectral(in, Backend::Cpu), glow);
    double peak = 0, worst = 0, emitted_peak = 0, star_peak = 0;
    for (size_t i = 0; i < sum.pixels.size(); ++i) {
      peak = std::max(peak, double(sum.pixels[i]));
      emitted_peak = std::max(emitted_peak, double(emitted.pixels[i]));
      star_peak = std::max(star_peak, double(star_light.pixels[i]));
      worst = std::max(worst, double(std::fabs(sum.pixels[i] - star_light.pixels[i] - emitted.pixels[i])));
    }
    EXPECT_GT(emitted_peak, 0.05 * star_peak) << "the emission must be visible beside the stars";
    EXPECT_LT(worst, 1e-5 * peak) << "method " << int(method);
  }
}

// A filter change on a fixed wavelength range re-resolves the emission too:
// the same accumulators resolved for new filters equal a model built with them.
TEST(SpectralEmission, FilterChangeNeedsNoNewMarch) {
  const UniformCube cube(8, 0.2f);
  SpectralSettings s;
  s.lo_um = 0.33;
  s.hi_um = 1.0;
  const std::vector<SpectralEmission> emission = {{0.5007}, {0.0, {0.5, 0.5}, 0.0, 0.0}};
  SpectralModel m = build_spectral_model(filters({"B", "V"}), {}, s, emission);
  SpectralRenderInputs in;
  in.density = &cube.grid;
  in.model = &m;
  in.emission = {{nullptr, 1.0f}, {nullptr, 1.0f}};
  in.camera = cube.camera;
  const Image acc = render_spectral(in, Backend::Cpu);
  set_filters(m, filters({"R", "sdss_g"}));
  const Image changed = resolve_filters(acc, m);
  const SpectralModel fresh = build_spectral_model(filters({"R", "sdss_g"}), {}, s, emission);
  in.model = &fresh;
  const Image direct = resolve_filters(render_spectral(in, Backend::Cpu), fresh);
  for (size_t i = 0; i < direct.pixels.size(); ++i) {
    EXPECT_GT(direct.pixels[i], 0.0f);
    EXPECT_NEAR(changed.pixels[i], direct.pixels[i], 1e-5 * direct.pixels[i]);
  }
}

TEST(SpectralEmission, BadComponentsAreRefused) {
  const auto f = filters({"B", "V"});
  SpectralSettings s;
  auto message = [&](std::vector<SpectralEmission> e) -> std::string {
    try {
      build_spectral_model(f, {}, s, e);
    } catch (const Error& err) {
      return err.what();
    }
    return "";
  };
  EXPECT_NE(message({{0.80}}).find("spectral.emission.0.line_nm"), std::string::npos);  // beyond B, V
  EXPECT_NE(message({{0.0, {1.0, -2.0}, 0.0, 0.0}}).find("spectral.emission.0.continuum"), std::string::npos);
  EXPECT_NE(message({{0.5}, {0.0, {1.0}, 0.9, 1.2}}).find("spectral.emission.1.range_nm"), std::string::npos);
  s.basis = 10;  // 4 continua x 10 elements: 40 numbers per ray
  EXPECT_NE(message(std::vector<SpectralEmission>(4, {0.0, {1.0}, 0.0, 0.0})).find("at most 32"), std::string::npos);
}

}  // namespace
}  // namespace nebula::spectral
