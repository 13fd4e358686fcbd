// A scene with a [spectral] table end to end: one plane per band (built-in
// filters and a user file), each named with its pivot wavelength, exactly the
// spectral library's image on the same inputs; the fast methods within their
// stated error of the double integral; files written with the planes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "illumination/optical_depth_bake.h"
#include "imageio/image_output.h"
#include "pipeline/render_scene.h"
#include "pipeline/render_session.h"
#include "pipeline/run_setup.h"
#include "pipeline/spectral_scene.h"
#include "pipeline/table_source.h"
#include "scene/scene_file.h"
#include "scene/test_files.h"
#include "spectral/spectral_renderer.h"
#include "spectral/spectral_test_scene.h"
#include "tables/table_file.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

class SpectralScene : public testing::TempDirTest {
 protected:
  // Tables generated on first use go to a cache of this test's own, with few
  // photons (their noise does not matter here: every image compared uses the same table).
  testing::ScopedEnv cache_{"NEBULA_CACHE_DIR", path("cache")};
  void SetUp() override {
    // A table without Monte-Carlo noise, of a real table's shape (docs/spectral.md, "Tables"): the
    // scenes below read it, so the methods' differences are theirs, not the table's noise.
    write_table(testing::make_test_table(10.0, 1001, AngularBinning::UniformTheta, 180, 0.6), path("smooth.h5"), true);
  }
  static RenderOptions options() {
    RenderOptions o;
    o.table_photons = 1000;
    return o;
  }
  // Three top-hat filters 10 nm wide at 450, 550 and 700 nm (bands n450, n550,
  // n700), where the band model is nearly the spectral integral, each band
  // reading the smooth table: a scene's bands, [filters] and [dust] tables.
  std::string narrow_filters() {
    std::string bands = "bands = [", files = "[filters]\n", tables = "[dust]\ntables = { ";
    for (int nm : {450, 550, 700}) {
      const std::string name = "n" + std::to_string(nm), sep = nm == 700 ? "" : ", ";
      write_text(name + ".txt", "# 10 nm top hat\n" + std::to_string(nm - 6) + " 0\n" + std::to_string(nm - 5) +
                                    " 1\n" + std::to_string(nm + 5) + " 1\n" + std::to_string(nm + 6) + " 0\n");
      bands += "\"" + name + "\"" + sep;
      files += name + " = \"" + name + ".txt\"\n";
      tables += name + " = \"smooth.h5\"" + sep;
    }
    return bands + "]\n" + files + tables + " }\n";
  }
  RenderOutput render(const std::string& spectral) { return render_scene(scene(spectral), options()); }
  Scene scene(const std::string& spectral, const std::vector<std::string>& overrides = {}) {
    write_text("ha.txt", "# H-alpha, 6 nm\n650 0\n653 1\n659 1\n662 0\n");
    return load_scene(write_text("scene.toml", "bands = [\"sdss_g\", \"V\", \"Halpha\"]\n"
                                               "[filters]\nHalpha = \"ha.txt\"\n"
                                               "[density]\nprocedural = { n = 24, size_pc = 2.0 }\n"
                                               + std::string(spectral.find("tables = false") == std::string::npos
                                                                 ? "[dust]\ntables = { sdss_g = \"smooth.h5\", "
                                                                   "V = \"smooth.h5\", Halpha = \"smooth.h5\" }\n"
                                                                 : "") +
                                               "[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
                                               "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\n"
                                               "width = 40\nheight = 32\nexposure = 0.02\n"
                                               "[render]\ndiffuse_photons = 524288\n"
                                               // Methods compared with the double integral pixel by pixel: one ray
                                               // each (star pixels would make the reference's march 10 times longer).
                                               "star_pixels = false\n"
                                               "[spectral]\n" + spectral),
                      overrides);
  }

};

double number_entry(const ImageMetadata& m, const std::string& key) {
  for (const auto& [k, v] : m.entries)
    if (k == key) return v.number();
  ADD_FAILURE() << "no metadata " << key;
  return 0;
}

using spectral::testing::worst_relative_per_band;

TEST_F(SpectralScene, OnePlanePerFilterWithItsPivot) {
  // Without the light between voxels, so that the inputs below are all there is (it has a test of its own).
  const Scene s = scene("method = \"projection\"\nbasis = 4\n", {"render.multiple_scattering=none"});
  const RenderOutput out = render_scene(s, options());
  EXPECT_EQ(out.image.bands, (std::vector<std::string>{"sdss_g", "V", "Halpha"}));
  ASSERT_TRUE(out.report.spectral);
  EXPECT_EQ(out.report.renderer, "spectral");
  EXPECT_EQ(out.report.spectral->basis, 4);
  EXPECT_EQ(out.report.spectral->filters.size(), 3u);
  // Long band names go by plane in numeric keys (pivot_nm_b1), short ones by name.
  EXPECT_NEAR(number_entry(out.metadata, "pivot_nm_b1"), 470, 10);  // SDSS g: 4702 A (Doi et al. 2010)
  EXPECT_NEAR(number_entry(out.metadata, "pivot_nm_V"), 551, 5);
  EXPECT_NEAR(number_entry(out.metadata, "pivot_nm_b3"), 656, 1);
  // Exactly the spectral library's image on inputs assembled by hand.
  const SceneBands sb = scene_bands(s);
  std::vector<std::pair<std::string, Passband>> filters;
  for (size_t b = 0; b < 3; ++b) filters.push_back({s.bands[b], sb.filters[b]});
  const spectral::SpectralModel m =
      spectral::build_spectral_model(filters, {{s.stars[0].temperature_K}}, spectral_settings(s));
  const BakeResult bake = bake_star_depths_cpu(s.density, {s.stars[0].position});
  spectral::SpectralRenderInputs in;
  in.density = &s.density;
  in.model = &m;
  in.lights.push_back({s.stars[0].position, s.stars[0].luminosity_lsun, &bake.tau_v[0]});
  in.camera = make_camera(s.camera);
  in.star_pixels = s.star_pixels;
  const BandTables tables = resolve_tables(s, {Backend::Cpu, 1000});  // the cached table the render used
  in.table = tables.per_band[0].get();
  ASSERT_TRUE(in.table);
  EXPECT_EQ(out.report.spectral->table_nodes, 3);
  const Image expected = spectral::resolve_filters(spectral::render_spectral(in, Backend::Cpu), m);
  ASSERT_EQ(expected.pixels.size(), out.image.pixels.size());
  double peak = 0;
  for (size_t i = 0; i < expected.pixels.size(); ++i) {
    EXPECT_EQ(expected.pixels[i], out.image.pixels[i]) << i;
    peak = std::max(peak, double(out.image.pixels[i]));
  }
  EXPECT_GT(peak, 0.0);
  // Written and read back with its planes and pivots (HDF5 and FITS; PNG coloured by pivot).
  for (const char* name : {"a.h5", "a.fits"}) {
    write_image(out.image, path(name), out.metadata, false);
    ImageMetadata back;
    const Image read = read_image(path(name), &back);
    EXPECT_EQ(read.bands, out.image.bands);
    EXPECT_EQ(read.pixels, out.image.pixels);
    EXPECT_NEAR(number_entry(back, "pivot_nm_b3"), 656, 1);
  }
  if (openimageio_available()) write_image(out.image, path("a.png"), out.metadata, false);
}

// Against the double integral (the reference, 400 samples, the table read at
// each wavelength's own depth) on this scene, with the voxels' table (the
// default): the projection with 4 elements within 1% per pixel with signal
// (the goal); the light-density basis, whose family also spans
// temperature, with 6 (4 give 1.4% here); the voxel-light method with 4; the
// analytic integral (the report's C_T / lambda) against the double integral on
// that attenuation. And the table matters: the thin limit (tables = false) is
// further from it than the goal.
TEST_F(SpectralScene, FastMethodsAgainstTheDoubleIntegral) {
  const Image ref = render("method = \"double\"\nwavelengths = 400\n").image;
  const double projection = worst_relative_per_band(render("basis = 4\n").image, ref);
  const double light = worst_relative_per_band(render("method = \"light_density\"\nbasis = 6\n").image, ref);
  const Image inverse_ref = render("method = \"double\"\nwavelengths = 400\nattenuation = \"inverse\"\n").image;
  const double analytic = worst_relative_per_band(render("method = \"analytic\"\nattenuation = \"inverse\"\n").image, inverse_ref);
  const double voxel = worst_relative_per_band(render("method = \"voxel_light\"\nbasis = 4\n").image, ref);
  const double pre = worst_relative_per_band(render("method = \"preintegrated\"\n").image, ref);
  const RenderOutput thin = render("basis = 4\ntables = false\n");
  const double thin_error = worst_relative_per_band(thin.image, ref);
  std::printf("  largest pixel error against the double integral: projection (4) %.2e, light-density (6) %.2e, "
              "analytic %.2e, voxel light (4) %.2e, pre-integrated %.2e; the thin limit %.2e\n",
              projection, light, analytic, voxel, pre, thin_error);
  EXPECT_LT(projection, 1e-2);
  EXPECT_LT(voxel, 1e-2);
  EXPECT_LT(pre, 1e-2);
  EXPECT_LT(light, 1e-2);
  EXPECT_LT(analytic, 1e-2);
  EXPECT_GT(thin_error, 1e-2);
  EXPECT_EQ(thin.report.spectral->table_nodes, 0);
  EXPECT_TRUE(thin.report.tables.empty());
}

// Emission ([[spectral.emission]]): an H-alpha line where the dust is and a
// flat continuum, added to the starlight. The line shows in the H-alpha
// filter and not in sdss_g; the projection (4 elements) is within 1% per pixel
// of the double integral (400 samples) with the emission in.
TEST_F(SpectralScene, EmissionThroughTheFilters) {
  const std::string glow = "[[spectral.emission]]\nline_nm = 656.28\nscale = 2e3\n"
                           "[[spectral.emission]]\ncontinuum = [20.0]\n";
  const RenderOutput plain = render("basis = 4\n");
  const RenderOutput lit = render("basis = 4\n" + glow);
  EXPECT_EQ(number_entry(lit.metadata, "spec_emission"), 2);
  const size_t plane = lit.image.plane_size();
  double g_gain = 0, ha_gain = 0, ha_plain = 0;
  for (size_t i = 0; i < plane; ++i) {
    g_gain += lit.image.pixels[i] - plain.image.pixels[i];
    ha_gain += lit.image.pixels[2 * plane + i] - plain.image.pixels[2 * plane + i];
    ha_plain += plain.image.pixels[2 * plane + i];
  }
  EXPECT_GT(ha_gain, 0.5 * ha_plain) << "the line must show in the H-alpha filter";
  EXPECT_GT(g_gain, 0.0);  // the continuum
  const Image ref = render("method = \"double\"\nwavelengths = 400\n" + glow).image;
  const double err = worst_relative_per_band(lit.image, ref);
  std::printf("  with emission: projection (4) against the double integral %.2e\n", err);
  EXPECT_LT(err, 1e-2);
}

// Light between voxels (docs/spectral.md, "Light between voxels"), against
// the band renderer's: through three filters 10 nm wide, where the band model
// (one extinction ratio and one star power per band) is nearly the spectral
// integral, each filter's light between voxels (the render less the same with
// render.multiple_scattering = "none") agrees in total with the band
// renderer's within 4 standard errors of the difference of their means over 4
// seeds of the fields' photons each, plus the two renderers' difference in the
// single-scattered light (the band model's own error, which the light between
// voxels inherits).
TEST_F(SpectralScene, LightBetweenVoxelsAgreesWithTheBandRenderer) {
  const auto totals = [&](bool spectral, const std::vector<std::string>& overrides) {
    const std::string text = narrow_filters() +
                             "[density]\nprocedural = { n = 24, size_pc = 2.0 }\n"
                             "[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
                             "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\nwidth = 40\nheight = 32\n"
                             "[render]\ndiffuse_photons = 131072\n" +
                             std::string(spectral ? "[spectral]\nmethod = \"projection\"\nbasis = 4\n" : "");
    const RenderOutput out = render_scene(load_scene(write_text("narrow.toml", text), overrides), options());
    std::vector<double> t(3, 0.0);
    const size_t plane = out.image.plane_size();
    for (size_t b = 0; b < 3; ++b)
      for (size_t i = 0; i < plane; ++i) t[b] += out.image.pixels[b * plane + i];
    if (spectral && overrides.size() == 1) {  // a seed, so the light between voxels
      EXPECT_EQ(out.report.multiple_scattering, "diffuse");
      EXPECT_TRUE(out.report.diffuse.done);
      EXPECT_EQ(out.report.diffuse.names.size(), 3u);  // one band per table node
    }
    return t;
  };
  const std::vector<double> band_single = totals(false, {"render.multiple_scattering=none", "render.diffuse_seed=1"});
  const std::vector<double> spectral_single = totals(true, {"render.multiple_scattering=none", "render.diffuse_seed=1"});
  constexpr int kSeeds = 4;
  std::vector<std::vector<double>> band, spectral;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    band.push_back(totals(false, {"render.diffuse_seed=" + std::to_string(seed)}));
    spectral.push_back(totals(true, {"render.diffuse_seed=" + std::to_string(seed)}));
  }
  for (size_t b = 0; b < 3; ++b) {
    double mb = 0, ms = 0, vb = 0, vs = 0;
    for (int k = 0; k < kSeeds; ++k) {
      mb += (band[k][b] - band_single[b]) / kSeeds;
      ms += (spectral[k][b] - spectral_single[b]) / kSeeds;
    }
    for (int k = 0; k < kSeeds; ++k) {
      vb += std::pow(band[k][b] - band_single[b] - mb, 2) / (kSeeds - 1);
      vs += std::pow(spectral[k][b] - spectral_single[b] - ms, 2) / (kSeeds - 1);
    }
    const double sigma = std::sqrt((vb + vs) / kSeeds);
    const double model = std::fabs(spectral_single[b] / band_single[b] - 1.0) * mb;
    std::printf("  filter %zu: light between voxels, spectral / band %.4f (standard error %.4f; single scattering "
                "%.4f); %.0f%% of the image\n",
                b, ms / mb, sigma / mb, spectral_single[b] / band_single[b], 100 * mb / (mb + band_single[b]));
    EXPECT_GT(mb, 0.2 * band_single[b]);  // the light between voxels is a large part here
    EXPECT_LT(std::fabs(ms - mb), 4 * sigma + model);
  }
}

// Near a star a voxel's chord sees the star over a wide range of angles, and
// the band marcher takes the table's mean over them (tables/chord_phase.h);
// the spectral marcher does the same, so through filters 10 nm wide (where
// the band model is nearly the spectral integral) a star inside a uniform
// sphere renders alike per pixel with either renderer, its brightest pixels
// included (with the midpoint angle alone they differ by 5% there).
TEST_F(SpectralScene, ChordsNearAStarTakeThePhaseMeanAsTheBandRenderer) {
  const auto render_sphere = [&](bool spectral) {
    const std::string text = narrow_filters() +
                             "[density.procedural]\nn = 32\nsize_pc = 2.0\nstar = [0.5, 0.5, 0.5]\n"
                             "bubble_offset = 0.0\nbubble_radius = 0.4\nbubble_tau = 2.5\nshell_tau = 0.0\n"
                             "cloud_tau = 0.0\nfar_multiplier = 1.0\nnoise_amplitude = 0.0\n"
                             "[[stars]]\nluminosity_lsun = 1e4\nclass = \"B0V\"\n"
                             "[camera]\nkind = \"orthographic\"\nposition = [1.0, 1.0, 20.0]\nlook_at = [1.0, 1.0, 1.0]\n"
                             "up = [0.0, 1.0, 0.0]\northo_width = 2.0\nwidth = 48\nheight = 48\n"
                             "[render]\nmultiple_scattering = \"none\"\n" +
                             std::string(spectral ? "[spectral]\nmethod = \"projection\"\nbasis = 4\n" : "");
    return render_scene(load_scene(write_text("sphere.toml", text)), options()).image;
  };
  const Image band = render_sphere(false), spectral = render_sphere(true);
  ASSERT_EQ(band.pixels.size(), spectral.pixels.size());
  const size_t plane = band.plane_size();
  for (size_t b = 0; b < 3; ++b) {
    double peak = 0, worst = 0;
    for (size_t i = 0; i < plane; ++i) peak = std::max(peak, double(band.pixels[b * plane + i]));
    ASSERT_GT(peak, 0.0);
    for (size_t i = 0; i < plane; ++i) {
      const double ref = band.pixels[b * plane + i];
      if (ref > 1e-3 * peak) worst = std::max(worst, std::fabs(spectral.pixels[b * plane + i] / ref - 1.0));
    }
    std::printf("  filter %zu: spectral / band, worst pixel %.2e\n", b, worst);
    EXPECT_LT(worst, 1e-2);
  }
}

// The light between voxels is baked star by star, so the image of two stars
// of very different spectra is the sum of the images of each star alone (the
// same photons: each star's field has the scene's seed) to float rounding.
TEST_F(SpectralScene, LightBetweenVoxelsAddsStarByStar) {
  const auto render_stars = [&](const std::string& stars) {
    const std::string text = "bands = [\"B\", \"V\", \"R\"]\n[dust]\ntables = { B = \"smooth.h5\", V = "
                             "\"smooth.h5\", R = \"smooth.h5\" }\n[density]\nprocedural = { n = 16, size_pc = 2.0 }\n" +
                             stars +
                             "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\nwidth = 32\nheight = 24\n"
                             // One ray per pixel: each image's star pixels lie around its own stars, so
                             // sums of images would be sampled apart there.
                             "[render]\ndiffuse_photons = 65536\nstar_pixels = false\n"
                             "[spectral]\nmethod = \"projection\"\nbasis = 4\n";
    return render_scene(load_scene(write_text("stars.toml", text)), options());
  };
  const std::string hot = "[[stars]]\nluminosity_lsun = 2e5\ntemperature_K = 41400\nposition = [0.6, 1.0, 1.0]\n";
  const std::string cool = "[[stars]]\nluminosity_lsun = 2e5\ntemperature_K = 3850\nposition = [1.4, 1.0, 1.1]\n";
  const RenderOutput both = render_stars(hot + cool);
  const Image a = render_stars(hot).image, b = render_stars(cool).image;
  EXPECT_TRUE(both.report.diffuse.done);
  EXPECT_EQ(both.report.diffuse.stars, 2u);
  double peak = 0, worst = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    peak = std::max(peak, double(both.image.pixels[i]));
    worst = std::max(worst, std::fabs(double(both.image.pixels[i]) - a.pixels[i] - b.pixels[i]));
  }
  EXPECT_GT(peak, 0.0);
  EXPECT_LT(worst, 1e-5 * peak);
}

// Albedo and g varying with wavelength ([spectral.dust]): each table node
// reads a table for its own (a, g), generated and cached like the band
// renderer's. A curve that is constant at the dust's a and g names the same
// cached table at every node, so the image is the constant dust's (light
// between voxels included) to float rounding; a varying one reports each
// node's (a, g) and table and changes the image.
TEST_F(SpectralScene, AlbedoAndGVaryingWithWavelength) {
  const auto curve_scene = [&](const std::string& dust, const std::vector<std::string>& overrides = {}) {
    const std::string text = "bands = [\"B\", \"V\", \"R\"]\n[density]\nprocedural = { n = 16, size_pc = 2.0 }\n"
                             "[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
                             "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\nwidth = 32\nheight = 24\n"
                             "[render]\ndiffuse_photons = 32768\n[spectral]\nmethod = \"projection\"\nbasis = 4\n" +
                             dust;
    return load_scene(write_text("curve.toml", text), overrides);
  };
  const RenderOutput constant = render_scene(curve_scene(""), options());
  const RenderOutput flat = render_scene(
      curve_scene("[spectral.dust]\nwavelength_nm = [400, 800]\nalbedo = [0.6, 0.6]\ng = [0.6, 0.6]\n"), options());
  double peak = 0, worst = 0;
  for (size_t i = 0; i < constant.image.pixels.size(); ++i) {
    peak = std::max(peak, double(constant.image.pixels[i]));
    worst = std::max(worst, std::fabs(double(flat.image.pixels[i]) - constant.image.pixels[i]));
  }
  EXPECT_GT(peak, 0.0);
  EXPECT_LT(worst, 1e-5 * peak);
  const RenderOutput varying = render_scene(
      curve_scene("[spectral.dust]\nwavelength_nm = [350, 550, 900]\nalbedo = [0.4, 0.6, 0.7]\ng = [0.7, 0.6, 0.5]\n"),
      options());
  ASSERT_TRUE(varying.report.spectral);
  const SpectralReport& r = *varying.report.spectral;
  ASSERT_EQ(r.node_albedo.size(), 3u);
  EXPECT_GT(r.node_albedo.front(), r.node_albedo.back());  // the reddest node first: the largest albedo
  EXPECT_LT(r.node_g.front(), r.node_g.back());
  EXPECT_EQ(varying.report.tables.size(), 3u);
  EXPECT_TRUE(varying.report.diffuse.done);
  double change = 0;
  for (size_t i = 0; i < constant.image.pixels.size(); ++i)
    change = std::max(change, std::fabs(double(varying.image.pixels[i]) - constant.image.pixels[i]) / peak);
  EXPECT_GT(change, 0.01);
  // Bad curves, and what a curve cannot go with, name the key.
  testing::expect_error([&] { curve_scene("[spectral.dust]\nalbedo = [0.5]\n"); },
                        {"curve.toml", "spectral.dust.wavelength_nm", "required"});
  testing::expect_error([&] { curve_scene("[spectral.dust]\nwavelength_nm = [400, 800]\nalbedo = [0.5]\n"); },
                        {"curve.toml", "spectral.dust.albedo", "1 values for 2 wavelengths"});
  testing::expect_error(
      [&] { render_scene(curve_scene("[spectral.dust]\nwavelength_nm = [800, 400]\ng = [0.5, 0.6]\n"), options()); },
      {"curve.toml", "spectral.dust.wavelength_nm", "increasing"});
  testing::expect_error(
      [&] { render_scene(curve_scene("[spectral.dust]\nwavelength_nm = [400, 800]\ng = [0.5, 1.0]\n"), options()); },
      {"curve.toml", "spectral.dust.g", "(-1, 1)"});
  testing::expect_error([&] {
    render_scene(curve_scene("[spectral.dust]\nwavelength_nm = [400, 800]\ng = [0.5, 0.6]\n",
                             {"spectral.method=double"}), options());
  }, {"curve.toml", "spectral.method", "tables = false"});
}

// Prepared once (model, tables, depth bakes, the light between voxels'
// fields), each view is what a whole render with that camera gives, bit for
// bit: the viewer's frames and `nebula render` cannot differ.
TEST_F(SpectralScene, PreparedOnceEachViewIsTheWholeRender) {
  const Scene s = scene("method = \"projection\"\nbasis = 4\n", {"render.diffuse_photons=131072"});
  ASSERT_EQ(s.multiple_scattering, MultipleScattering::Diffuse);
  const std::shared_ptr<const PreparedSpectral> prepared = prepare_spectral(s, options());
  ASSERT_NE(prepared->diffuse, nullptr);
  CameraSettings moved = s.camera;
  moved.position = {2.5, -2, 1.6};
  Image first;
  for (const CameraSettings& camera : {s.camera, moved}) {
    Scene whole = s;
    whole.camera = camera;
    const RenderOutput expected = render_spectral_scene(whole, options());
    const RenderOutput view = render_prepared_spectral(*prepared, camera);
    ASSERT_EQ(view.image.pixels.size(), expected.image.pixels.size());
    for (size_t i = 0; i < view.image.pixels.size(); ++i)
      ASSERT_EQ(view.image.pixels[i], expected.image.pixels[i]) << "pixel value " << i;
    EXPECT_EQ(view.report.multiple_scattering, "diffuse");
    EXPECT_GT(view.report.diffuse.seconds, 0.0);  // the preparation's bake, reported with each view
    if (first.pixels.empty()) first = view.image;
  }
  double moved_by = 0, total = 0;
  const Image last = render_prepared_spectral(*prepared, moved).image;
  for (size_t i = 0; i < first.pixels.size(); ++i) {
    moved_by += std::fabs(last.pixels[i] - first.pixels[i]);
    total += first.pixels[i];
  }
  EXPECT_GT(moved_by, 0.05 * total);  // the second view is another view
}

// A preparation after an edit keeps what the edit left unchanged (the
// viewer's Filters panel, sessions, sweeps): new filters within the basis'
// range keep the tables, depth bakes, fields and basis, for every method
// that takes new filters on its basis; a star's power keeps its depth bake
// alone; a star moved keeps nothing. The image is a fresh preparation's, bit
// for bit, each time.
TEST_F(SpectralScene, APreparationKeepsWhatTheEditLeftUnchanged) {
  const std::vector<std::string> pinned = {"render.diffuse_photons=65536", "spectral.range_um=[0.3, 1.0]"};
  const auto expect_fresh_image = [&](const PreparedSpectral& p, const Scene& s) {
    const RenderOutput view = render_prepared_spectral(p, s.camera);
    const RenderOutput fresh = render_spectral_scene(s, options());
    EXPECT_EQ(view.image.bands, s.bands);
    ASSERT_EQ(view.image.pixels.size(), fresh.image.pixels.size());
    for (size_t i = 0; i < view.image.pixels.size(); ++i)
      ASSERT_EQ(view.image.pixels[i], fresh.image.pixels[i]) << "pixel value " << i;
  };
  const auto kept = [](const PreparedSpectral& p) {
    return std::vector<bool>{p.report.spectral->basis_kept, p.report.bake.reused, p.report.diffuse.reused};
  };
  const std::vector<bool> all = {true, true, true};
  for (const char* method : {"projection", "voxel_light", "preintegrated"}) {
    SCOPED_TRACE(method);
    const std::string spectral = "method = \"" + std::string(method) + "\"\nbasis = 4\n";
    const Scene a = scene(spectral, pinned);
    const std::shared_ptr<const PreparedSpectral> first = prepare_spectral(a, options());
    ASSERT_NE(first->diffuse, nullptr);
    EXPECT_EQ(kept(*first), std::vector<bool>({false, false, false}));
    std::vector<std::string> other = pinned;
    other.push_back("bands=[\"V\", \"sdss_g\"]");  // two planes instead of three, on the same table
    other.push_back("dust.tables={V = \"smooth.h5\", sdss_g = \"smooth.h5\"}");
    const Scene b = scene(spectral, other);
    const std::shared_ptr<const PreparedSpectral> second = prepare_spectral(b, options(), first.get());
    EXPECT_EQ(kept(*second), all);
    EXPECT_EQ(second->bake, first->bake);
    EXPECT_EQ(second->diffuse, first->diffuse);
    EXPECT_EQ(second->report.diffuse.seconds, first->report.diffuse.seconds);  // the bake reported is the one kept
    expect_fresh_image(*second, b);
    expect_fresh_image(*first, a);  // the first preparation is left as it was
  }
  const std::string spectral = "method = \"projection\"\nbasis = 4\n";
  const Scene a = scene(spectral, pinned);
  const std::shared_ptr<const PreparedSpectral> first = prepare_spectral(a, options());
  // A star's power: its depth bake is kept; the fields (its light) and the model are made again.
  std::vector<std::string> dimmer = pinned;
  dimmer.push_back("stars.0.luminosity_lsun=1e5");
  const Scene dim = scene(spectral, dimmer);
  const std::shared_ptr<const PreparedSpectral> again = prepare_spectral(dim, options(), first.get());
  EXPECT_EQ(kept(*again), std::vector<bool>({false, true, false}));
  EXPECT_EQ(again->bake, first->bake);
  EXPECT_NE(again->diffuse, first->diffuse);
  expect_fresh_image(*again, dim);
  // A star moved: nothing is kept.
  std::vector<std::string> moved = pinned;
  moved.push_back("stars.0.position=[1.1, 1, 1]");
  const std::shared_ptr<const PreparedSpectral> elsewhere = prepare_spectral(scene(spectral, moved), options(), first.get());
  EXPECT_EQ(kept(*elsewhere), std::vector<bool>({false, false, false}));
  // Unpinned, the range is the bands' span: new bands of another span take a new basis, nodes and fields...
  const std::string tables = "dust.tables={V = \"smooth.h5\", Halpha = \"smooth.h5\"}";
  const Scene narrow = scene(spectral, {"render.diffuse_photons=65536", "bands=[\"V\", \"Halpha\"]", tables});
  const std::shared_ptr<const PreparedSpectral> other = prepare_spectral(narrow, options(), first.get());
  EXPECT_EQ(kept(*other), std::vector<bool>({false, true, false}));
  EXPECT_LT(other->model.hi_um - other->model.lo_um, 0.7 - 0.35);
  expect_fresh_image(*other, narrow);
  // ... and bands of the same span (reordered) keep everything.
  const Scene reordered = scene(spectral, {"render.diffuse_photons=65536", "bands=[\"Halpha\", \"V\"]", tables});
  const std::shared_ptr<const PreparedSpectral> same = prepare_spectral(reordered, options(), other.get());
  EXPECT_EQ(kept(*same), all);
  expect_fresh_image(*same, reordered);
}

// Sweeps and the Python module render through a RenderSession: a [spectral]
// scene there is the spectral renderer's image, as `nebula render` gives it,
// its overrides applied (here the camera).
TEST_F(SpectralScene, ASessionRendersItWithTheSpectralRenderer) {
  const Scene s = scene("method = \"projection\"\nbasis = 4\n", {"render.diffuse_photons=65536"});
  RenderSession session = RenderSession::from_file(path("scene.toml"), {"render.diffuse_photons=65536"}, options());
  const RenderOutput first = session.render();
  ASSERT_TRUE(first.report.spectral.has_value());
  EXPECT_EQ(first.image.pixels, render_scene(s, options()).image.pixels);
  const RenderOutput moved = session.render({"camera.position=[2.5, -2, 1.6]"});
  Scene moved_scene = s;
  moved_scene.camera.position = {2.5, -2, 1.6};
  EXPECT_EQ(moved.image.pixels, render_scene(moved_scene, options()).image.pixels);
  EXPECT_NE(moved.image.pixels, first.image.pixels);
  // A camera edit kept the preparation whole: its depth bake, model and fields.
  EXPECT_FALSE(first.report.bake.reused);
  EXPECT_TRUE(moved.report.bake.reused);
  EXPECT_TRUE(moved.report.spectral->basis_kept);
  EXPECT_TRUE(moved.report.diffuse.reused);
  // A star's power: the depth bake alone is kept, and the image is the whole render's.
  const RenderOutput dimmer = session.render({"stars.0.luminosity_lsun=1e5"});
  EXPECT_TRUE(dimmer.report.bake.reused);
  EXPECT_FALSE(dimmer.report.diffuse.reused);
  EXPECT_EQ(dimmer.image.pixels,
            render_scene(scene("method = \"projection\"\nbasis = 4\n",
                               {"render.diffuse_photons=65536", "stars.0.luminosity_lsun=1e5"}),
                         options()).image.pixels);
}

TEST_F(SpectralScene, BadSettingsNameTheKeyAndWriteNothing) {
  testing::expect_error([&] { scene("basis = 0\n"); }, {"scene.toml", "spectral.basis", "1..16"});
  testing::expect_error([&] { scene("table_nodes = 5\n"); }, {"scene.toml", "spectral.table_nodes", "1..4"});
  testing::expect_error([&] { scene("tables = 1\n"); }, {"scene.toml", "spectral.tables", "true or false"});
  testing::expect_error([&] { render_scene(scene("range_um = [0.5, 0.6]\n"), RenderOptions{}); },
                        {"scene.toml", "spectral", "every filter"});
  testing::expect_error([&] { render_scene(scene("[[spectral.emission]]\nline_nm = 1500\n"), RenderOptions{}); },
                        {"scene.toml", "spectral.emission.0.line_nm", "outside the filters' span"});
  testing::expect_error([&] { render_scene(scene("", {"render.multiple_scattering=pyramid"}), options()); },
                        {"scene.toml", "render.multiple_scattering", "no pyramid"});
}

}  // namespace
}  // namespace nebula
