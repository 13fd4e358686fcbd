// The viewer without a window: the background bake and render, edits that
// change the picture as they should, a bad edit undone, the saved scene
// rendering the viewer's frame again bit for bit, and painting an axial map.
#include "viewer/viewer_session.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <chrono>
#include <cmath>
#include <numeric>
#include <thread>

#include "core/test_support.h"
#include "imageio/image_output.h"
#include "scene/scene_file.h"
#include "viewer/display_image.h"

namespace nebula::viewer {
namespace {

const char* kScene = R"(
[density]
procedural = { n = 16, size_pc = 2.0 }
[[stars]]
luminosity_lsun = 2e5
class = "O5V"
[camera]
position = [1.0, -2.5, 1.0]
look_at = [1.0, 1.0, 1.0]
width = 24
height = 20
exposure = 0.02
[render]
diffuse_photons = 8192
)";

class ViewerSession : public ::testing::Test, protected nebula::testing::ScratchDir {
 protected:
  ViewerSession() : ScratchDir("nebula_viewer") {}
  void SetUp() override { setenv("NEBULA_CACHE_DIR", path("cache").c_str(), 1); }
  ViewerOptions options() const {
    ViewerOptions o;
    o.table_photons = 1000;
    return o;
  }
  static Frame frame_of(Session& s, const CameraSettings& camera) {
    s.request(camera);
    s.wait_idle();
    std::optional<Frame> f = s.take_frame();
    EXPECT_TRUE(f.has_value());
    return f ? *f : Frame{};
  }
};

double total(const Image& image) { return std::accumulate(image.pixels.begin(), image.pixels.end(), 0.0); }

TEST_F(ViewerSession, HigherAlbedoBrightensTheDust) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  const CameraSettings camera = s.scene().camera;
  const Frame before = frame_of(s, camera);
  ASSERT_GT(total(before.image), 0);
  s.edit("dust.albedo", "0.9");
  s.wait_idle();
  EXPECT_TRUE(s.status().error.empty()) << s.status().error;
  const Frame after = frame_of(s, camera);
  EXPECT_GT(after.version, before.version);
  EXPECT_GT(total(after.image), 1.2 * total(before.image));  // 0.9 / 0.6 more light scattered, less extinction aside
  s.sync_scene();
  EXPECT_EQ(s.scene().dust.albedo[0], 0.9);
}

TEST_F(ViewerSession, ABadEditIsUndoneAndSaysWhy) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  const CameraSettings camera = s.scene().camera;
  const Frame before = frame_of(s, camera);
  s.edit("dust.albedo", "3");
  s.wait_idle();
  const std::string error = s.status().error;
  EXPECT_NE(error.find("dust.albedo"), std::string::npos) << error;
  EXPECT_NE(error.find("undone"), std::string::npos) << error;
  EXPECT_TRUE(s.source().overrides().empty());
  const Frame again = frame_of(s, camera);
  EXPECT_EQ(again.image.pixels, before.image.pixels);
}

TEST_F(ViewerSession, TheSavedSceneRendersTheSameImage) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  s.edit("dust.g", "0.8");
  s.edit("stars.0.luminosity_lsun", "5e4");
  CameraSettings camera = s.scene().camera;
  camera.position = {2.5f, -2.0f, 1.4f};
  camera.fov_deg = 33.3;
  const Frame shown = frame_of(s, camera);
  DisplaySettings display;
  display.stretch = Stretch::Log;
  const std::string text = s.saved_scene_text(camera, display, {});
  const Scene saved = load_scene_text(text, "saved.toml", ".");
  EXPECT_TRUE(saved.display == display);
  RenderOptions o;
  o.table_photons = 1000;
  const RenderOutput rendered = render_scene(saved, o);
  EXPECT_EQ(rendered.image.pixels, shown.image.pixels);
}

TEST_F(ViewerSession, AnEditKeepsTheBakesItDoesNotChange) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  const CameraSettings camera = s.scene().camera;
  frame_of(s, camera);
  EXPECT_FALSE(s.status().report.bake.reused);
  s.edit("dust.albedo", "0.8");  // the stars' depths do not depend on the albedo
  const Frame after_albedo = frame_of(s, camera);
  EXPECT_TRUE(s.status().report.bake.reused);
  EXPECT_FALSE(s.status().report.diffuse.reused);  // the field does
  // Taken over, not approximated: the frame is the edited scene's fresh render.
  RenderOptions o;
  o.table_photons = 1000;
  Scene edited = load_scene_text(kScene, "v.toml", ".", {"dust.albedo=0.8"});
  EXPECT_EQ(render_scene(edited, o).image.pixels, after_albedo.image.pixels);
  s.edit("stars.0.position", "[0.7, 1.0, 1.1]");  // a moved star is baked again
  frame_of(s, camera);
  EXPECT_FALSE(s.status().report.bake.reused);
}

// A [spectral] scene is prepared once: a moved camera renders the new view
// from the same bakes (the times they report do not change) and each frame is
// `nebula render`'s image of that view.
TEST_F(ViewerSession, ASpectralSceneIsBakedOnceForEveryView) {
  const std::string text = std::string(kScene) + "[spectral]\nmethod = \"projection\"\n";
  Session s(SceneSource(text, "v.toml", "."), options());
  CameraSettings camera = s.scene().camera;
  const Frame first = frame_of(s, camera);
  camera.position = {2.5f, -2.0f, 1.4f};
  const Frame second = frame_of(s, camera);
  const RunReport &a = first.report, &b = second.report;
  ASSERT_TRUE(b.spectral.has_value());
  EXPECT_GT(b.diffuse.seconds, 0.0);
  EXPECT_EQ(a.diffuse.seconds, b.diffuse.seconds);  // a field baked again would take a time of its own
  EXPECT_EQ(a.bake.seconds, b.bake.seconds);
  EXPECT_EQ(s.status().report.diffuse.seconds, b.diffuse.seconds);
  Scene moved = load_scene_text(text, "v.toml", ".");
  moved.camera = camera;
  RenderOptions o;
  o.table_photons = 1000;
  EXPECT_EQ(render_scene(moved, o).image.pixels, second.image.pixels);
  EXPECT_NE(first.image.pixels, second.image.pixels);
}

// The panel's filter choice is an edit of `bands`: the frame's planes are then
// the new filters' integrals, as `nebula render` gives them.
TEST_F(ViewerSession, ASpectralScenesFiltersChangeAtRunTime) {
  const std::string text = std::string(kScene) + "[spectral]\nmethod = \"projection\"\n";
  Session s(SceneSource(text, "v.toml", "."), options());
  const CameraSettings camera = s.scene().camera;
  const Frame before = frame_of(s, camera);
  const std::vector<std::string> sdss = {"sdss_g", "sdss_r", "sdss_i"};
  EXPECT_EQ(toml_strings(sdss), "[\"sdss_g\", \"sdss_r\", \"sdss_i\"]");
  // SDSS g, r, i lie within B-R's 0.36-0.90 um: the basis, tables and bakes are kept, the range
  // is kept in the scene, and the frame is `nebula render`'s image of the scene as it now stands.
  s.set_filters(sdss);
  const Frame after = frame_of(s, camera);
  EXPECT_TRUE(s.status().error.empty()) << s.status().error;
  ASSERT_EQ(after.image.bands, sdss);
  ASSERT_TRUE(s.status().report.spectral.has_value());
  EXPECT_TRUE(s.status().report.spectral->basis_kept);
  EXPECT_TRUE(s.status().report.diffuse.reused);
  const std::vector<std::string> kept = s.source().overrides();
  EXPECT_NE(std::find_if(kept.begin(), kept.end(),
                         [](const std::string& k) { return k.rfind("spectral.range_um=[0.3", 0) == 0; }),
            kept.end());
  RenderOptions o;
  o.table_photons = 1000;
  EXPECT_EQ(render_scene(load_scene_text(text, "v.toml", ".", kept), o).image.pixels, after.image.pixels);
  EXPECT_NE(before.image.pixels, after.image.pixels);
  // U reaches 0.30 um, outside that basis: the range kept goes, and the scene is prepared afresh.
  const std::vector<std::string> ubv = {"U", "B", "V"};
  s.set_filters(ubv);
  const Frame wider = frame_of(s, camera);
  EXPECT_TRUE(s.status().error.empty()) << s.status().error;
  ASSERT_EQ(wider.image.bands, ubv);
  EXPECT_FALSE(s.status().report.spectral->basis_kept);
  EXPECT_TRUE(s.status().report.bake.reused);  // the stars' depths do not depend on the filters
  EXPECT_FALSE(s.status().report.diffuse.reused);
  const std::vector<std::string> afresh = s.source().overrides();
  EXPECT_EQ(afresh, std::vector<std::string>{"bands=" + toml_strings(ubv)});
  EXPECT_EQ(render_scene(load_scene_text(text, "v.toml", ".", afresh), o).image.pixels, wider.image.pixels);
  EXPECT_THROW(s.set_filters({"no_such_filter"}), Error);
  EXPECT_THROW(toml_strings({"a\"b"}), Error);
}

TEST_F(ViewerSession, APreviewIsTheCoarserGridsQuickFrame) {
  ViewerOptions o = options();
  o.preview_coarsening = 1;
  Session s(SceneSource(kScene, "v.toml", "."), o);
  const CameraSettings camera = s.scene().camera;
  const Frame exact = frame_of(s, camera);
  EXPECT_FALSE(exact.preview);
  s.request(camera, true);
  s.wait_idle();
  const std::optional<Frame> quick = s.take_frame();
  ASSERT_TRUE(quick.has_value());
  EXPECT_TRUE(quick->preview);
  EXPECT_EQ(quick->image.width, camera.width);
  EXPECT_NE(quick->image.pixels, exact.image.pixels);
  // It is what the pipeline makes of the halved grid in the preview mode, bit for bit.
  RenderOptions ro;
  ro.table_photons = 1000;
  const Scene coarse = coarsened_scene(load_scene_text(kScene, "v.toml", "."), 1);
  const PreparedGrid prepared = prepare_grid(coarse, ro);
  EXPECT_EQ(render_prepared(prepared, camera, true).image.pixels, quick->image.pixels);
}

TEST_F(ViewerSession, AStarsTemperatureReplacesItsClass) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  const CameraSettings camera = s.scene().camera;
  const Frame hot = frame_of(s, camera);
  // The viewer's edit: the star's entry whole, with a temperature instead of the class.
  s.edit("stars.0", "{name = \"star 0\", position = [1, 1, 1], luminosity_lsun = 2e5, temperature_K = 5770}");
  const Frame cool = frame_of(s, camera);
  EXPECT_TRUE(s.status().error.empty()) << s.status().error;
  s.sync_scene();
  EXPECT_EQ(s.scene().stars[0].temperature_K, 5770);
  EXPECT_EQ(s.scene().stars[0].spectral_class, "");
  // The same bolometric luminosity: a Sun-like star puts far more of it in B, V and R than an O5V star.
  EXPECT_GT(total(cool.image), 2 * total(hot.image));
}

TEST_F(ViewerSession, TheTruthAccumulatesWhileTheCameraRests) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  const CameraSettings camera = s.scene().camera;
  frame_of(s, camera);
  s.set_truth(true);
  std::optional<TruthFrame> six;
  for (int i = 0; i < 600 && !(six && six->passes >= 6); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    six = s.truth();
  }
  s.set_truth(false);
  ASSERT_TRUE(six && six->passes >= 6);
  EXPECT_EQ(six->spp, 2 * six->passes);
  // The accumulation is the mean of `nebula truth` passes with seeds 1, 2, ..., its variance
  // the sum of theirs over K^2.
  Scene scene = s.scene();
  scene.camera = camera;
  const int K = six->passes;
  std::vector<double> mean(six->mean.pixels.size(), 0.0);
  double var = 0, first_var = 0, first_sum = 0;
  for (int k = 1; k <= K; ++k) {
    TruthOptions t;
    t.spp = 2;
    t.seed = uint64_t(k);
    const TruthRenderOutput out = truth_scene(scene, t);
    for (size_t i = 0; i < mean.size(); ++i) {
      mean[i] += out.image.pixels[i] / double(K);
      var += out.variance.pixels[i] / (double(K) * K);
      if (k == 1) first_var += out.variance.pixels[i], first_sum += out.image.pixels[i];
    }
  }
  double diff = 0, sum = 0;
  for (size_t i = 0; i < mean.size(); ++i) {
    diff += std::fabs(mean[i] - six->mean.pixels[i]);
    sum += mean[i];
  }
  EXPECT_NEAR(six->noise, std::sqrt(var) / sum, 1e-4 * six->noise);
  // The noise falls as 1/sqrt(K) against one pass (a third of slack for the variance estimates' own noise).
  EXPECT_LT(six->noise, 1.33 * std::sqrt(first_var) / first_sum / std::sqrt(double(K)));
  EXPECT_LT(diff, 1e-5 * sum);  // float rounding of the running mean only
}

TEST_F(ViewerSession, RecordedKeyframesAreSavedAsACameraPath) {
  Session s(SceneSource(kScene, "v.toml", "."), options());
  CameraKeyframe a, b;
  a.time = 0;
  a.position = {1, -2.5f, 1};
  a.look_at = b.look_at = {1, 1, 1};
  b.time = 2;
  b.position = {3, -2, 1.5f};
  b.fov_deg = 30;
  const Scene saved = load_scene_text(s.saved_scene_text(s.scene().camera, {}, {a, b}), "saved.toml", ".");
  ASSERT_TRUE(saved.camera_path.has_value());
  ASSERT_EQ(saved.camera_path->keys.size(), 2u);
  EXPECT_EQ(saved.camera_path->keys[1].position.x, 3.0f);
  EXPECT_EQ(saved.camera_path->keys[1].fov_deg, 30);
}

TEST_F(ViewerSession, TheWindowShowsWhatAPngHolds) {
  if (!openimageio_available()) GTEST_SKIP() << "PNG needs OpenImageIO";
  Session s(SceneSource(kScene, "v.toml", "."), options());
  const Frame f = frame_of(s, s.scene().camera);
  DisplaySettings d;
  d.stretch = Stretch::Asinh;
  d.auto_exposure = true;
  const Rgba8 rgba = display_image(f.image, 0.02, d, f.metadata);
  ImageMetadata m = f.metadata;
  m.display = d;
  m.exposure = 0.02;
  write_image(f.image, path("f.png"), m, false);
  const Image png = read_any_image(path("f.png"));
  ASSERT_EQ(png.width, rgba.width);
  for (int y = 0; y < png.height; ++y)
    for (int x = 0; x < png.width; ++x)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(int(std::lround(png.at(c, x, y) * 255)), int(rgba.pixels[(size_t(y) * png.width + x) * 4 + c]))
            << x << " " << y << " " << c;
}

// An axial scene with an empty map and a star on the axis at its middle: black
// (no dust to scatter, no emission, stars not drawn) until dust is painted.
const char* kAxialScene = R"(
bands = ["B", "V", "R"]
[axial]
synthetic = "empty"
nx = 64
nr = 32
length_pc = 2.0
origin = [0.0, 0.0, -1.0]
[[stars]]
position = [0.0, 0.0, 0.0]
luminosity_lsun = 2e4
class = "B0V"
[camera]
position = [6.0, 0.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov_deg = 30
width = 24
height = 24
[render]
diffuse_photons = 8192
)";

// Sums of the rows above and below the image's middle (camera up = +z = the axis).
std::pair<double, double> upper_lower(const Image& image) {
  double up = 0, down = 0;
  for (int c = 0; c < int(image.bands.size()); ++c)
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) (y < image.height / 2 ? up : down) += image.at(c, x, y);
  return {up, down};
}

Stroke dust_ring() {
  // A ring of tau_v 0.3 per texel around the axis 0.25 pc above the star
  // (texel 1/32 pc: x = 40 is z = +0.25, r = 8 texels 0.25 pc).
  Stroke s;
  s.brush.radius = 4;
  s.brush.value = 0.3f;
  s.dabs = {{40.5f, 8.5f}};
  return s;
}

TEST_F(ViewerSession, PaintedDustLightsUpWhereItWasPaintedAndErasingDarkensAgain) {
  Session s(SceneSource(kAxialScene, path("axial.toml"), dir_.string()), options());
  const CameraSettings camera = s.scene().camera;
  const Frame empty = frame_of(s, camera);
  EXPECT_EQ(total(empty.image), 0.0);
  EXPECT_FALSE(s.map_edited());

  const uint64_t version = s.status().version;
  const PaintResult r = s.paint(dust_ring());
  EXPECT_EQ(r.texels, 49u);  // lattice points within 4 of a point: 49
  EXPECT_TRUE(s.map_edited());
  EXPECT_EQ(s.axial_map()->empty_texels, s.axial_map()->count() - 49);
  const Frame painted = frame_of(s, camera);
  EXPECT_GT(painted.version, version);
  const auto [up, down] = upper_lower(painted.image);
  EXPECT_GT(up, 0.0);
  EXPECT_GT(up, 20 * down) << "the ring lies above the star: the light above the middle";

  Stroke erase;
  erase.brush.mode = BrushMode::Erase;
  erase.brush.shape = BrushShape::Square;
  erase.brush.radius = 100;
  erase.dabs = {{32, 16}};
  s.paint(erase);
  EXPECT_EQ(s.axial_map()->empty_texels, s.axial_map()->count());
  EXPECT_EQ(total(frame_of(s, camera).image), 0.0);

  s.revert_map();
  EXPECT_FALSE(s.map_edited());
}

TEST_F(ViewerSession, ThePaintedSceneSavedWithItsMapRendersTheSameImage) {
  Session s(SceneSource(kAxialScene, path("axial.toml"), dir_.string()), options());
  s.paint(dust_ring());
  Stroke glow;  // emission of band R alone, below the star
  glow.brush.radius = 3;
  glow.brush.value = 0.01f;
  glow.brush.plane.band = 2;
  glow.dabs = {{20.5f, 4.5f}};
  s.paint(glow);
  CameraSettings camera = s.scene().camera;
  camera.position = {5.0f, 1.0f, 2.0f};
  const Frame shown = frame_of(s, camera);
  ASSERT_GT(total(shown.image), 0.0);
  testing::expect_error([&] { s.saved_scene_text(camera, {}, {}); }, {"painted"});

  const std::vector<std::string> written = save_scene(s, camera, {}, {}, path("saved.toml"), false);
  ASSERT_EQ(written.size(), 2u);
  EXPECT_EQ(written[0], path("saved.map.h5"));
  EXPECT_EQ(written[1], path("saved.toml"));
  const Scene saved = load_scene(path("saved.toml"));
  ASSERT_TRUE(saved.axial.has_value());
  EXPECT_EQ(saved.axial->source, "file");
  EXPECT_EQ(saved.axial->path, path("saved.map.h5"));
  RenderOptions o;
  o.table_photons = 1000;
  const RenderOutput rendered = render_scene(saved, o);
  EXPECT_EQ(rendered.image.pixels, shown.image.pixels);

  // Saving again without --force: refused before anything is written.
  testing::expect_error([&] { save_scene(s, camera, {}, {}, path("saved.toml"), false); }, {"saved"});

  // The map file loads into a fresh session's empty map: the same frame.
  Session t(SceneSource(kAxialScene, path("axial.toml"), dir_.string()), options());
  t.load_map(path("saved.map.h5"));
  EXPECT_TRUE(t.map_edited());
  EXPECT_EQ(t.axial_map()->emission.size(), 3u);
  EXPECT_EQ(frame_of(t, camera).image.pixels, shown.image.pixels);
}

TEST_F(ViewerSession, BadMapsAndBrushesAreRefusedAndChangeNothing) {
  Session s(SceneSource(kAxialScene, path("axial.toml"), dir_.string()), options());
  {
    std::ofstream junk(path("junk.h5"));
    junk << "not HDF5";
  }
  testing::expect_error([&] { s.load_map(path("junk.h5")); }, {"junk.h5"});
  testing::expect_error([&] { s.load_map(path("missing.h5")); }, {"missing.h5"});
  Stroke bad = dust_ring();
  bad.brush.plane.band = 3;
  testing::expect_error([&] { s.paint(bad); }, {"brush: plane"});
  EXPECT_FALSE(s.map_edited());
  EXPECT_EQ(s.axial_map()->empty_texels, s.axial_map()->count());
  testing::expect_error([&] { brush_plane(s.scene(), "Ha", "--paint '1,2,3,4,Ha'"); },
                        {"--paint '1,2,3,4,Ha'", "plane 'Ha'", "B, V, R"});
  EXPECT_EQ(brush_plane(s.scene(), "V", "x").band, 1);
  EXPECT_TRUE(brush_plane(s.scene(), "tau_v", "x").is_tau());

  Session grid(SceneSource(kScene, "v.toml", "."), options());
  testing::expect_error([&] { grid.paint(dust_ring()); }, {"no [axial] map"});
}

}  // namespace
}  // namespace nebula::viewer
