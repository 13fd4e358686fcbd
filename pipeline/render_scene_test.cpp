// The pipeline end to end: what it renders is exactly the renderers' image on
// inputs assembled by hand from the same pieces, its errors name the scene key
// or option field, and its report says what it computed.
#include "pipeline/render_scene.h"
#include "pipeline/run_setup.h"
#include "illumination/passband.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "diffuse/diffuse_bake.h"
#include "montecarlo/table_conversion.h"
#include "scene/scene_file.h"
#include "scene/test_files.h"
#include "tables/table_file.h"

namespace nebula {
namespace {

class RenderScene : public testing::TempDirTest {
 protected:
  void SetUp() override { setenv("NEBULA_CACHE_DIR", path("cache").c_str(), 1); }
  Scene scene(const std::string& extra = "", const std::string& dust = "") {
    return load_scene(write_text("scene.toml", "[density]\nprocedural = { n = 16, size_pc = 2.0 }\n[dust]\n" + dust +
                                                   "\n[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
                                                   "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\n"
                                                   "width = 20\nheight = 16\nexposure = 0.02\n" +
                                                   extra));
  }
  RenderOptions options() const {
    RenderOptions o;
    o.table_photons = 1000;
    return o;
  }
};

// Equal planes, to a relative `tolerance` per pixel (0: bit for bit).
bool same_plane(const Image& a, const Image& b, int band, double tolerance = 0) {
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const double u = a.at(band, x, y), v = b.at(band, x, y);
      if (std::fabs(u - v) > tolerance * std::max(std::fabs(u), std::fabs(v))) return false;
    }
  return true;
}

TEST_F(RenderScene, IsTheRenderersImageOnItsInputs) {
  const Scene s = scene();
  const RenderOutput out = render_scene(s, options());
  // The same render assembled by hand from the pipeline's pieces.
  const SceneBands sb = scene_bands(s);
  const BandTables tables = resolve_tables(s, {Backend::Cpu, 1000, false});
  const BakeResult bake = bake_star_depths_cpu(s.density, {s.stars[0].position});
  RenderInputs in;
  in.density = &s.density;
  for (size_t b = 0; b < 3; ++b) in.bands.push_back(RenderBand{sb.bands[b], tables.per_band[b].get(), nullptr});
  in.stars.push_back(BakedStar{sb.stars[0], &bake.tau_v[0]});
  std::vector<DiffuseBand> diffuse_bands;
  for (size_t b = 0; b < 3; ++b) {
    DiffuseBand d;
    static_cast<Band&>(d) = sb.bands[b];
    d.table = tables.per_band[b].get();
    diffuse_bands.push_back(d);
  }
  DiffuseBakeOptions diffuse;
  diffuse.degree = resolved_order(s.diffuse, s.dust.g);
  diffuse.cells = s.diffuse.cells;
  diffuse.photons = s.diffuse.photons;
  diffuse.seed = s.diffuse.seed;
  const DiffuseField field = bake_diffuse(s.density, diffuse_bands, sb.stars, diffuse, Backend::Cpu);
  in.diffuse = &field;
  in.camera = make_camera(s.camera);
  in.exposure = 1.0f;  // the pixels are radiance whatever camera.exposure says (0.02 here)
  const Image expected = render_cpu(in, nullptr);
  ASSERT_EQ(out.image.pixels.size(), expected.pixels.size());
  for (int b = 0; b < 3; ++b) EXPECT_TRUE(same_plane(out.image, expected, b)) << "band " << b;
  float peak = 0;
  for (float v : out.image.pixels) peak = std::max(peak, v);
  EXPECT_GT(peak, 0.0f);

  const RunReport& r = out.report;
  EXPECT_EQ(r.renderer, "grid");
  EXPECT_EQ(r.multiple_scattering, "diffuse");
  EXPECT_TRUE(r.diffuse.done);
  EXPECT_EQ(r.diffuse.bands, 3u);
  EXPECT_EQ(r.diffuse.photons_per_band, s.diffuse.photons);
  for (double noise : r.diffuse.noise) EXPECT_GT(noise, 0.0);
  EXPECT_EQ(r.mode, "exact");
  EXPECT_EQ(r.width, 20);
  EXPECT_EQ(r.height, 16);
  ASSERT_EQ(r.bands.size(), 3u);
  for (const BandReport& b : r.bands) EXPECT_TRUE(b.scatters) << b.name;
  ASSERT_EQ(r.tables.size(), 1u);
  EXPECT_EQ(r.tables[0].bands, (std::vector<std::string>{"B", "V", "R"}));
  EXPECT_TRUE(r.bake.done);
  EXPECT_EQ(r.bake.stars, 1u);
  EXPECT_EQ(r.bake.cells, s.density.shape.count());
  EXPECT_EQ(r.pyramid.size(), 1u);
  EXPECT_GE(r.total_seconds, r.render_seconds);
  bool has_mode = false;
  for (const auto& [key, value] : out.metadata.entries) has_mode = has_mode || (key == "mode" && value == "exact");
  EXPECT_TRUE(has_mode);
  EXPECT_EQ(out.metadata.exposure, 0.02);  // recorded, not applied
}

const MetaValue* find_entry(const ImageMetadata& m, const std::string& key) {
  for (const auto& [k, v] : m.entries)
    if (k == key) return &v;
  return nullptr;
}

double number_entry(const ImageMetadata& m, const std::string& key) {
  const MetaValue* v = find_entry(m, key);
  EXPECT_TRUE(v != nullptr && v->is_number()) << key;
  return v != nullptr ? v->number() : std::nan("");
}

// Issue 16: the metadata an astronomer needs, typed, from the scene and the
// pipeline's own numbers (not from a file written by the code under test).
TEST_F(RenderScene, MetadataRecordsTheRunTyped) {
  const Scene s = load_scene(write_text("meta.toml", "[density]\nprocedural = { n = 16, size_pc = 2.0 }\n"
                                                     "[[stars]]\nname = \"central\"\nposition = [0.5, 0.25, -0.5]\n"
                                                     "luminosity_lsun = 2e5\nclass = \"O5V\"\n"
                                                     "[camera]\nposition = [1, -2.5, 1]\nlook_at = [1, 1, 1]\nwidth = 20\nheight = 16\nexposure = 0.02\n"),
                             {"dust.albedo={B = 0.6, V = 0.7, R = 0.6}"});
  const SceneBands sb = scene_bands(s);
  const ImageMetadata m = pipeline_detail::scene_metadata(s, sb, s.camera, "exact");
  EXPECT_EQ(m.units, "solLum pc-2 sr-1");
  EXPECT_EQ(m.exposure, 0.02);
  EXPECT_EQ(number_entry(m, "albedo_V"), 0.7);
  EXPECT_EQ(number_entry(m, "albedo_B"), s.dust.albedo[0]);
  EXPECT_EQ(number_entry(m, "R_V"), s.dust.R_V);
  EXPECT_EQ(number_entry(m, "ext_V"), 1.0);
  EXPECT_EQ(find_entry(m, "cam_width")->kind, MetaValue::Kind::Integer);
  EXPECT_EQ(number_entry(m, "cam_height"), 16);
  EXPECT_EQ(number_entry(m, "cam_fov_deg"), s.camera.fov_deg);
  EXPECT_EQ(number_entry(m, "stars"), 1);
  EXPECT_EQ(find_entry(m, "star1_name")->text, "central");
  EXPECT_EQ(find_entry(m, "star1_class")->text, "O5V");
  EXPECT_EQ(number_entry(m, "star1_x_pc"), 0.5);
  EXPECT_EQ(number_entry(m, "star1_z_pc"), -0.5);
  EXPECT_EQ(number_entry(m, "star1_L_Lsun"), 2e5);
  EXPECT_EQ(number_entry(m, "star1_T_K"), s.stars[0].temperature_K);
  for (size_t b = 0; b < 3; ++b) {
    EXPECT_EQ(number_entry(m, "star1_P_" + s.bands[b]), double(sb.stars[0].power[b]));
    // The pivot wavelength lies inside the filter, near its mean.
    const double pivot = number_entry(m, "pivot_nm_" + s.bands[b]);
    EXPECT_NEAR(pivot, mean_wavelength_nm(sb.filters[b]), 15.0) << s.bands[b];
  }
  EXPECT_LT(number_entry(m, "pivot_nm_B"), number_entry(m, "pivot_nm_V"));
  EXPECT_LT(number_entry(m, "pivot_nm_V"), number_entry(m, "pivot_nm_R"));
  EXPECT_EQ(find_entry(m, "DATE")->text.size(), 19u);
  EXPECT_EQ(find_entry(m, "software")->text.rfind("nebula ", 0), 0u);
  EXPECT_FALSE(find_entry(m, "git_commit")->text.empty());
  // The resolved scene: the override is in it and it loads as the same scene.
  EXPECT_NE(m.scene_text.find("albedo = { B = "), std::string::npos) << m.scene_text;
  const Scene again = load_scene_text(m.scene_text, "resolved", path(""));
  EXPECT_EQ(again.dust.albedo, s.dust.albedo);
  EXPECT_EQ(again.stars[0].name, "central");
}

// The world coordinates agree with the rays the camera traces: the angle of a
// pixel's ray from the view axis (perspective: TAN, fisheye: ARC), or its
// offset across the view (orthographic).
TEST(CameraWcs, MatchesTheCameraRays) {
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  for (const Projection p : {Projection::Perspective, Projection::Fisheye, Projection::Orthographic}) {
    CameraSettings c;
    c.projection = p;
    c.position = {1, -3, 0.5};
    c.look_at = {0.5, 0.5, 0};
    c.up = {0, 0, 1};
    c.fov_deg = 35;
    c.ortho_width = 4;
    c.width = p == Projection::Fisheye ? 64 : 80;
    c.height = 64;
    const Camera cam = make_camera(c);
    MetaEntries w = pipeline_detail::camera_wcs(c);
    auto get = [&](const std::string& k) {
      for (const auto& [key, v] : w)
        if (key == k) return v;
      ADD_FAILURE() << k;
      return MetaValue();
    };
    const double crpix1 = get("CRPIX1").number(), crpix2 = get("CRPIX2").number();
    const double d1 = get("CDELT1").number(), d2 = get("CDELT2").number();
    for (const auto& [px, py] : std::vector<std::pair<int, int>>{{0, 0}, {10, 50}, {40, 31}, {63, 5}, {30, 60}}) {
      // FITS pixel centres: x + 1, and rows counted from the bottom.
      const double x = d1 * (px + 1 - crpix1), y = d2 * (c.height - py - crpix2);
      Vec3 origin, dir;
      if (!cam.ray(px, py, origin, dir)) continue;
      if (p == Projection::Orthographic) {
        EXPECT_EQ(get("CUNIT1").text, "pc");
        EXPECT_NEAR(dot(origin - cam.position, cam.right), x, 1e-5);
        EXPECT_NEAR(dot(origin - cam.position, cam.up), y, 1e-5);
        continue;
      }
      const double across = std::hypot(double(dot(dir, cam.right)), double(dot(dir, cam.up)));
      const double angle = std::atan2(across, double(dot(dir, cam.forward)));
      const double r = std::hypot(x, y);
      if (p == Projection::Perspective) {
        EXPECT_EQ(get("CTYPE1").text, "OFLN-TAN");
        EXPECT_NEAR(std::tan(angle) * kDeg, r, 1e-4) << px << "," << py;
      } else {
        EXPECT_EQ(get("CTYPE1").text, "OFLN-ARC");
        EXPECT_NEAR(angle * kDeg, r, 2e-3) << px << "," << py;
      }
      // The direction on the sky: +x along the camera's right, +y along its up.
      if (r > 0) {
        EXPECT_NEAR(dot(dir, cam.right) / std::hypot(dot(dir, cam.right), dot(dir, cam.up)), x / r, 1e-4);
      }
    }
  }
}

// A table named for one band changes that band's plane and no other.
TEST_F(RenderScene, ABandsTableFileChangesThatBandOnly) {
  TabulateParams p;
  p.albedo = 0.7;
  p.g = 0.5;
  p.tau_bins = 101;
  p.binning = AngularBinning::UniformTheta;
  p.photons_per_row = 2000;
  p.seed = 7;  // not the cache's table
  write_table(to_table(tabulate(p, Backend::Cpu)), path("t07.h5"), true);
  const std::string dust = "albedo = { B = 0.6, V = 0.7, R = 0.6 }\ng = { B = 0.6, V = 0.5, R = 0.6 }\n";
  const Scene with_file = scene("", dust + "tables = { V = \"t07.h5\" }");
  const RenderOutput a = render_scene(with_file, options());
  const Scene without = scene("", dust);
  const RenderOutput b = render_scene(without, options());
  // The other planes to the march's transmittance cut (a ray ends where every
  // band's transmittance is below 1e-4, and V's, through the field's forward
  // peak, depends on V's table): 2e-7 apart in a star pixel's many rays.
  const double cut = 1e-4;
  EXPECT_TRUE(same_plane(a.image, b.image, 0, cut));
  EXPECT_FALSE(same_plane(a.image, b.image, 1, cut));
  EXPECT_TRUE(same_plane(a.image, b.image, 2, cut));
  ASSERT_EQ(a.report.tables.size(), 2u);
  EXPECT_EQ(a.report.tables[1].origin, TableOrigin::File);
  EXPECT_EQ(a.report.tables[1].bands, (std::vector<std::string>{"V"}));
}

// A grey band is the V band with the star's whole luminosity: the same
// dust (A/A_V = 1, V's albedo and g), so the image is V's scaled by L / L_V,
// the diffuse field included (its photons carry the star's power linearly).
TEST_F(RenderScene, TheGreyBandIsVWithTheWholeLuminosity) {
  Scene v = scene("[render]\ndiffuse_photons = 65536\n", "albedo = 0.6\ng = 0.6\n");
  v.bands = {"V"};
  v.dust.albedo = {0.6};
  v.dust.g = {0.6};
  v.dust.table_files = {""};
  Scene grey = v;
  grey.bands = {"grey"};
  const RenderOutput a = render_scene(v, options());
  const RenderOutput b = render_scene(grey, options());
  const double scale = scene_bands(grey).stars[0].power[0] / double(scene_bands(v).stars[0].power[0]);
  EXPECT_GT(scale, 10.0);  // an O5V star puts little of its light in V
  double sum_v = 0, sum_grey = 0, worst = 0;
  for (int y = 0; y < a.image.height; ++y)
    for (int x = 0; x < a.image.width; ++x) {
      const double expected = scale * a.image.at(0, x, y);
      sum_v += expected;
      sum_grey += b.image.at(0, x, y);
      worst = std::max(worst, std::fabs(b.image.at(0, x, y) - expected));
    }
  ASSERT_GT(sum_v, 0.0);
  // Single precision throughout: the images agree to rounding.
  EXPECT_NEAR(sum_grey / sum_v, 1.0, 1e-5);
  EXPECT_LT(worst / (sum_v / (a.image.width * a.image.height)), 1e-3);
}

// An emitting cube whose edge x = 1 splits the middle pixel column of a
// telescope image in two: with k x k rays over each pixel's area (k even) the
// column is exactly half as bright as the inside; at the centre it would be
// all or nothing.
template <class F>
void expect_error_naming(F f, const std::string& key) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected an error naming " << key;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

Scene edge_scene(int samples_per_pixel) {
  Scene s;
  s.path = "edge";
  s.bands = {"V"};
  s.density.shape.nx = s.density.shape.ny = s.density.shape.nz = 8;
  s.density.shape.voxel = 0.125f;
  s.density.tau_v.assign(512, 1e-3f);
  s.emission = {std::vector<float>(512, 1.0f)};
  s.dust.albedo = {0.0};
  s.dust.g = {0.6};
  s.dust.table_files = {""};
  s.multiple_scattering = MultipleScattering::None;
  s.camera.projection = Projection::Orthographic;
  s.camera.position = {1.0f, 0.5f, -1.0f};
  s.camera.look_at = {1.0f, 0.5f, 0.5f};
  s.camera.up = {0, 1, 0};
  s.camera.ortho_width = 0.9;  // 9 pixels of 0.1: column 4 spans x in [0.95, 1.05]
  s.camera.width = 9;
  s.camera.height = 3;
  s.samples_per_pixel = samples_per_pixel;
  return s;
}

TEST_F(RenderScene, SamplesPerPixelAverageThePixelsArea) {
  for (int n : {4, 16}) {
    const Scene s = edge_scene(n);
    const RenderOutput fast = render_scene(s, options());
    TruthOptions t;
    t.spp = 2 * n;
    const TruthRenderOutput truth = truth_scene(s, t);
    // Which side column 2 lies on depends on the camera's handedness.
    Vec3 o, d;
    make_camera(s.camera).ray(2, 1, o, d);
    const int in_x = o.x < 1.0f ? 2 : 6, out_x = 8 - in_x;
    for (const Image* image : {&fast.image, &truth.image}) {
      const float inside = image->at(0, in_x, 1), edge = image->at(0, 4, 1), outside = image->at(0, out_x, 1);
      ASSERT_GT(inside, 0.0f) << n;
      EXPECT_NEAR(edge / inside, 0.5, 1e-4) << n << (image == &fast.image ? " fast" : " truth");
      EXPECT_EQ(outside, 0.0f) << n;
    }
    EXPECT_NEAR(fast.image.at(0, in_x, 1) / truth.image.at(0, in_x, 1), 1.0, 1e-3) << n;
  }
  // Bad input names the key, or the truth's option.
  expect_error_naming([&] { render_scene(edge_scene(8), options()); }, "render.samples_per_pixel");
  TruthOptions odd;
  odd.spp = 6;
  expect_error_naming([&] { truth_scene(edge_scene(4), odd); }, "spp");
}

TEST_F(RenderScene, ErrorsNameTheKeyOrTheField) {
  Scene s = scene();
  s.multiple_scattering = MultipleScattering::Pyramid;
  s.pyramid_levels = 9;  // a 16^3 grid allows 3
  try {
    render_scene(s, options());
    ADD_FAILURE() << "9 levels accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "render.levels");
    EXPECT_NE(std::string(e.what()).find("9 exceeds the 3"), std::string::npos) << e.what();
  }
  s.pyramid_levels = 0;
  s.multiple_scattering = MultipleScattering::Diffuse;
  RenderOptions o = options();
  o.smooth_step = 1e-4f;
  try {
    render_scene(s, o);
    ADD_FAILURE() << "a smooth step of 1e-4 accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "smooth_step");
  }
  TruthOptions t;
  t.spp = 1;
  try {
    truth_scene(s, t);
    ADD_FAILURE() << "1 spp accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "spp");
  }
}

// The report counts the pixels at the star's image that the exact traversal
// marched with many rays each: the star sits at the image's centre (20 x 16
// pixels, on four pixels' corner), so 6 x 6 pixels, the four at it cut into
// cells; none when they are off or in the smooth mode.
TEST_F(RenderScene, StarPixelsAreReported) {
  RenderOutput out = render_scene(scene(), options());
  EXPECT_EQ(out.report.star_pixels, 36);
  EXPECT_GT(out.report.star_pixel_cells, 36);
  EXPECT_GT(out.report.star_pixel_rays, 36 * 16);
  out = render_scene(scene("[render]\nstar_pixels = false\n"), options());
  EXPECT_EQ(out.report.star_pixels, 0);
  EXPECT_EQ(out.report.star_pixel_rays, 0);
  RenderOptions smooth = options();
  smooth.smooth_step = 0.5;
  out = render_scene(scene(), smooth);
  EXPECT_EQ(out.report.star_pixel_rays, 0);
}

TEST_F(RenderScene, PyramidLevelsAreReported) {
  const Scene s = scene("[render]\nlevels = 2\n");
  EXPECT_EQ(s.multiple_scattering, MultipleScattering::Pyramid);  // levels ask for the pyramid
  const RenderOutput out = render_scene(s, options());
  ASSERT_EQ(out.report.pyramid.size(), 3u);
  EXPECT_EQ(out.report.pyramid[2].shape.nx, 4);
  EXPECT_EQ(out.report.pyramid[2].width, 5);
}

TEST_F(RenderScene, AxialMapsAndTheTruthRunThroughTheSamePipeline) {
  const Scene axial = load_scene(write_text(
      "axial.toml",
      "bands = [\"B\", \"V\"]\n[axial]\nsynthetic = \"shells\"\nnx = 32\nnr = 16\nemission_scale = 1.0\n"
      "[[stars]]\nposition = [0.0, 0.0, 1.0]\nluminosity_lsun = 10\nclass = \"B0V\"\n"
      "[render]\ndiffuse_photons = 20000\n"
      "[camera]\nposition = [4.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\nwidth = 12\nheight = 12\n"));
  const RenderOutput a = render_scene(axial, options());
  ASSERT_TRUE(a.report.axial.has_value());
  EXPECT_EQ(a.report.renderer, "axial");
  EXPECT_EQ(a.report.axial->nx, 32);
  EXPECT_EQ(a.report.axial->skip, "distance");
  EXPECT_EQ(a.report.tables.size(), 1u);
  EXPECT_TRUE(a.report.bake.done);
  EXPECT_EQ(a.report.bake.cells, 32u * 16u);
  for (float v : a.image.pixels) EXPECT_TRUE(std::isfinite(v));

  TruthOptions t;
  t.spp = 4;
  const TruthRenderOutput truth = truth_scene(scene(), t);
  EXPECT_EQ(truth.image.width, 20);
  EXPECT_EQ(truth.variance.pixels.size(), truth.image.pixels.size());
  ASSERT_TRUE(truth.report.truth.has_value());
  EXPECT_EQ(truth.report.truth->paths, 20u * 16u * 4u * 3u);
  EXPECT_EQ(truth.variance_metadata.units, "solLum2 pc-4 sr-2");
  EXPECT_EQ(truth.metadata.units, "solLum pc-2 sr-1");
  EXPECT_EQ(truth.metadata.exposure, 0.02);
  t.axial_voxels = 64;
  const TruthRenderOutput axial_truth = truth_scene(axial, t);
  ASSERT_TRUE(axial_truth.report.truth.has_value());
  EXPECT_EQ(axial_truth.report.truth->axial_grid.nz, 64);  // along the map's longer side, its length (32 x 16 texels)
  EXPECT_EQ(axial_truth.report.truth->axial_grid.nx, 64);
  EXPECT_EQ(axial_truth.image.width, 12);
}

// Deformations through the pipeline: the scene's tables reach the renderer
// (the image changes; the report's mode names them), the resolved scene in
// the metadata carries them, and the truth refuses them, naming the key.
TEST_F(RenderScene, AxialDeformationsRunThroughThePipeline) {
  const std::string base =
      "bands = [\"B\", \"V\"]\n[axial]\nsynthetic = \"lopsided\"\nnx = 32\nnr = 16\nemission_scale = 1.0\n"
      "[camera]\nkind = \"orthographic\"\nposition = [4.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\northo_width = 2.4\n"
      "width = 24\nheight = 24\n";
  const Scene plain = load_scene(write_text("plain.toml", base));
  const Scene deformed = load_scene(write_text(
      "deformed.toml", base + "[axial.colour_deform]\namplitude = 0.9\n[axial.shape_deform]\namplitude = 0.4\n"));
  const RenderOutput a = render_scene(plain, options());
  const RenderOutput b = render_scene(deformed, options());
  double diff = 0, sum = 0;
  for (size_t i = 0; i < a.image.pixels.size(); ++i) {
    ASSERT_TRUE(std::isfinite(b.image.pixels[i]));
    diff += std::fabs(double(a.image.pixels[i]) - b.image.pixels[i]);
    sum += std::fabs(double(a.image.pixels[i]));
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_GT(diff, 0.05 * sum);
  EXPECT_NE(b.report.mode.find("colour deformation fbm"), std::string::npos) << b.report.mode;
  EXPECT_NE(b.report.mode.find("shape deformation fbm"), std::string::npos) << b.report.mode;
  EXPECT_NE(b.metadata.scene_text.find("colour_deform"), std::string::npos);
  TruthOptions t;
  t.spp = 2;
  testing::expect_error([&] { truth_scene(deformed, t); }, {"axial.colour_deform", "undeformed map"});
}

// The truth traces an axial map voxelized in the map's own frame, the camera
// moved with it: on a tilted axis, seen from the side, with emission only
// and no scattering (which the axial marcher integrates without
// approximation but its step), the two images agree up to the truth's noise,
// the voxels' staircase and the marcher's step around the small emitting
// core. Measured: flux 0.6% apart at a step of 0.1 texel and 256 voxels
// (3.9% at the default step of 0.5); bounds 2% and, per pixel, 3% of the
// peak. A frame turned or mirrored the wrong way would put the cloud elsewhere.
TEST_F(RenderScene, TheTruthTracesAnAxialMapInItsOwnFrame) {
  const Scene axial = load_scene(write_text(
      "axial_tilted.toml",
      "bands = [\"V\"]\n[axial]\nsynthetic = \"lopsided\"\nnx = 32\nnr = 16\nlength_pc = 2.0\n"
      "origin = [0.1, -0.3, 0.2]\naxis = [1.0, 2.0, 2.0]\nemission_scale = 1.0\ntau_scale = 0.05\nstep_texels = 0.1\n[dust]\nalbedo = 0.0\n"
      "[camera]\nposition = [4.0, -3.0, 1.0]\nlook_at = [0.8, 1.0, 1.5]\nfov_deg = 45\nwidth = 24\nheight = 24\n"));
  const RenderOutput fast = render_scene(axial, options());
  TruthOptions t;
  t.spp = 16;
  const TruthRenderOutput truth = truth_scene(axial, t);
  float peak = 0;
  for (float v : fast.image.pixels) peak = std::max(peak, v);
  ASSERT_GT(peak, 0.0f);
  double worst = 0, sum_f = 0, sum_t = 0, var = 0;
  for (size_t i = 0; i < fast.image.pixels.size(); ++i) {
    const double d = std::fabs(fast.image.pixels[i] - truth.image.pixels[i]) - 4 * std::sqrt(truth.variance.pixels[i]);
    worst = std::max(worst, d / peak);
    sum_f += fast.image.pixels[i];
    sum_t += truth.image.pixels[i];
    var += truth.variance.pixels[i];
  }
  std::printf("axial emission: worst pixel beyond 4 sigma %.4f of the peak, flux ratio %.4f +- %.4f\n", worst,
              sum_t / sum_f, std::sqrt(var) / sum_f);
  EXPECT_LT(worst, 0.03);
  EXPECT_NEAR(sum_t / sum_f, 1.0, 0.02 + 4 * std::sqrt(var) / sum_f);
}

}  // namespace
}  // namespace nebula

namespace nebula {
namespace {

TEST_F(RenderScene, ACoarsenedSceneKeepsTheDustAndBakesApart) {
  const Scene fine = scene("[render]\ndiffuse_photons = 8192\n");
  const Scene coarse = coarsened_scene(fine, 1);
  EXPECT_EQ(coarse.density.shape.nx, (fine.density.shape.nx + 1) / 2);
  EXPECT_EQ(coarse.density.shape.voxel, 2 * fine.density.shape.voxel);
  // The dust's mass: sum of tau_v l^2 over the voxels.
  double mass_fine = 0, mass_coarse = 0;
  for (float t : fine.density.tau_v) mass_fine += double(t) * fine.density.shape.voxel * fine.density.shape.voxel;
  for (float t : coarse.density.tau_v)
    mass_coarse += double(t) * coarse.density.shape.voxel * coarse.density.shape.voxel;
  EXPECT_NEAR(mass_coarse, mass_fine, 1e-5 * mass_fine);
  EXPECT_EQ(coarse.diffuse.cells, std::max(1, fine.diffuse.cells / 2));
  EXPECT_EQ(coarse.diffuse.photons, std::max<uint64_t>(4096, fine.diffuse.photons / 4));
  EXPECT_NE(coarse.grid_source, fine.grid_source);  // never mistaken for the fine grid's bakes
  // Its own bakes: a preparation of it reuses nothing of the fine grid's.
  const PreparedGrid p_fine = prepare_grid(fine, options());
  const PreparedGrid p_coarse = prepare_grid(coarse, options(), p_fine);
  EXPECT_FALSE(p_coarse.report.bake.reused);
  EXPECT_EQ(p_coarse.bake.tau_v[0].size(), coarse.density.shape.count());
  EXPECT_THROW(coarsened_scene(fine, -1), Error);
  // Asking more levels than the grid has stops at a grid of 2 voxels.
  EXPECT_EQ(coarsened_scene(fine, 30).density.shape.nx, 2);
}

TEST_F(RenderScene, APreparationLeftWholeGivesTheSameFrame) {
  const std::string few_photons = "[render]\ndiffuse_photons = 8192\n";
  const Scene first = scene(few_photons);
  const PreparedGrid before = prepare_grid(first, options());
  const Scene edited = scene(few_photons, "albedo = 0.8");
  const PreparedGrid reused = prepare_grid(edited, options(), before);  // `before` stays whole
  EXPECT_TRUE(reused.report.bake.reused);
  EXPECT_FALSE(before.bake.tau_v.empty());
  const PreparedGrid fresh = prepare_grid(edited, options());
  EXPECT_EQ(render_prepared(reused, edited.camera).image.pixels, render_prepared(fresh, edited.camera).image.pixels);
}

// The field is reused while nothing it depends on changes; its response's
// taper is one of those things (the photons are not: they do not depend on it).
TEST_F(RenderScene, ChangingTheTaperRemakesTheField) {
  const std::string few_photons = "[render]\ndiffuse_photons = 8192\n";
  const Scene plain = scene(few_photons), again = scene(few_photons),
              tapered_scene = scene(few_photons + "diffuse_taper = \"lanczos\"\n");
  const PreparedGrid first = prepare_grid(plain, options());
  ASSERT_TRUE(first.report.diffuse.done);
  EXPECT_FALSE(first.report.diffuse.lanczos) << "auto at g = 0.6: untapered";
  const PreparedGrid same = prepare_grid(again, options(), first);
  EXPECT_TRUE(same.report.diffuse.reused);
  const PreparedGrid tapered = prepare_grid(tapered_scene, options(), first);
  EXPECT_FALSE(tapered.report.diffuse.reused);
  EXPECT_TRUE(tapered.report.diffuse.lanczos);
  EXPECT_NE(render_prepared(tapered, tapered_scene.camera).image.pixels,
            render_prepared(first, plain.camera).image.pixels);
}

}  // namespace
}  // namespace nebula
