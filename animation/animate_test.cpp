// `nebula animate` end to end on a small scene: frames at keyframe times are
// `nebula render` of that camera bit for bit, the frame count and names,
// resume without redoing finished frames, and refusals that write nothing.
#include "animation/animate.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/test_support.h"
#include "imageio/image_output.h"
#include "scene/scene_file.h"

namespace nebula {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"(
[density]
procedural = { n = 16, size_pc = 2.0 }
[[stars]]
luminosity_lsun = 2e5
class = "O5V"
[camera]
position = [1.0, -2.5, 1.0]
look_at = [1.0, 1.0, 1.0]
width = 20
height = 16
exposure = 0.02
[render]
diffuse_photons = 20000
[[animation.keyframes]]
time = 0.0
position = [1.0, -2.5, 1.0]
[[animation.keyframes]]
time = 0.5
position = [3.5, -1.0, 1.2]
fov_deg = 30
[[animation.keyframes]]
time = 1.0
position = [4.0, 1.0, 1.5]
look_at = [1.2, 1.0, 1.0]
)";

class Animate : public ::testing::Test, protected testing::ScratchDir {
 protected:
  Animate() : ScratchDir("nebula_animate") {}
  void SetUp() override { setenv("NEBULA_CACHE_DIR", path("cache").c_str(), 1); }
  Scene scene(const std::vector<std::string>& overrides = {}) const {
    return load_scene_text(kScene, "path.toml", ".", overrides);
  }
  AnimateOptions options(const std::string& pattern = "frames/f_%03d.h5") const {
    AnimateOptions o;
    o.pattern = path(pattern);
    o.fps = 4;  // frames at 0, 0.25, 0.5, 0.75, 1: the keys are frames 0, 2 and 4
    o.render.table_photons = 1000;
    return o;
  }
};

bool same_pixels(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.bands == b.bands && a.pixels == b.pixels;
}

TEST_F(Animate, FramesAtKeyTimesAreRendersOfTheKeysCameraBitForBit) {
  const Scene s = scene();
  const AnimateResult r = animate(s, options());
  EXPECT_EQ(r.plan.count(), 5);
  EXPECT_EQ(r.rendered, 5);
  EXPECT_EQ(r.skipped, 0);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(fs::exists(path("frames/f_00" + std::to_string(k) + ".h5"))) << k;
  EXPECT_TRUE(fs::exists(r.manifest));
  for (const auto& [frame, key] : {std::pair<int, int>{0, 0}, {2, 1}, {4, 2}}) {
    Scene at_key = s;
    const CameraKeyframe& k = s.camera_path->keys[size_t(key)];
    at_key.camera.position = k.position;
    at_key.camera.look_at = k.look_at;
    at_key.camera.up = k.up;
    at_key.camera.fov_deg = k.fov_deg;
    RenderOptions o;
    o.table_photons = 1000;
    const RenderOutput rendered = render_scene(at_key, o);
    const Image written = read_image(path("frames/f_00" + std::to_string(frame) + ".h5"));
    EXPECT_TRUE(same_pixels(written, rendered.image)) << "frame " << frame;
  }
  // Between keys the camera moves: frame 1 is neither frame 0 nor frame 2.
  const Image f0 = read_image(path("frames/f_000.h5")), f1 = read_image(path("frames/f_001.h5")),
              f2 = read_image(path("frames/f_002.h5"));
  EXPECT_FALSE(same_pixels(f0, f1));
  EXPECT_FALSE(same_pixels(f1, f2));
  // Nothing but the frames and the run's record.
  EXPECT_EQ(std::distance(fs::directory_iterator(path("frames")), fs::directory_iterator()), 6);
}

TEST_F(Animate, ResumeRendersOnlyTheMissingFrames) {
  const Scene s = scene();
  animate(s, options());
  const Image f3 = read_image(path("frames/f_003.h5"));
  fs::remove(path("frames/f_003.h5"));
  fs::remove(path("frames/f_004.h5"));
  const auto old = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (int k = 0; k < 3; ++k) fs::last_write_time(path("frames/f_00" + std::to_string(k) + ".h5"), old);
  AnimateOptions o = options();
  o.resume = true;
  const AnimateResult r = animate(s, o);
  EXPECT_EQ(r.rendered, 2);
  EXPECT_EQ(r.skipped, 3);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(fs::last_write_time(path("frames/f_00" + std::to_string(k) + ".h5")), old) << k;
  EXPECT_TRUE(same_pixels(read_image(path("frames/f_003.h5")), f3));
}

TEST_F(Animate, ExistingFramesAreRefusedUnlessForcedOrResumed) {
  const Scene s = scene();
  animate(s, options());
  const auto before = fs::last_write_time(path("frames/f_000.h5"));
  AnimateOptions o = options();
  o.existing_hint = " (HINT)";
  try {
    animate(s, o);
    ADD_FAILURE() << "existing frames were not refused";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "pattern");
    EXPECT_NE(std::string(e.what()).find("already holds 5 frames"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(HINT)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::last_write_time(path("frames/f_000.h5")), before);
  // A resumed run must be the same run: another frame rate is refused.
  o.resume = true;
  o.fps = 8;
  try {
    animate(s, o);
    ADD_FAILURE() << "a resume of another run was not refused";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "resume");
  }
  o.resume = false;
  o.force = true;
  o.fps = 4;
  EXPECT_EQ(animate(s, o).rendered, 5);
}

TEST_F(Animate, BadInputWritesNothing) {
  Scene no_path = scene();
  no_path.camera_path.reset();
  testing::expect_error([&] { animate(no_path, options()); }, {"path.toml", "animation", "keyframes"});
  const Scene s = scene();
  EXPECT_THROW(animate(s, options("frames/f.h5")), ParameterError);
  EXPECT_THROW(animate(s, options("frames/f_%03d.jpg")), ParameterError);
  AnimateOptions o = options();
  o.fps = -1;
  EXPECT_THROW(animate(s, o), ParameterError);
  o = options();
  o.to = 7;
  EXPECT_THROW(animate(s, o), ParameterError);
  o = options();
  o.video = path("movie.mp4");  // frames are .h5: no video
  EXPECT_THROW(animate(s, o), ParameterError);
  EXPECT_FALSE(fs::exists(path("frames")));
  EXPECT_FALSE(fs::exists(path("movie.mp4")));
}

TEST_F(Animate, AFailedBakeLeavesNothingBehind) {
  // 4 pyramid levels on a 16^3 grid (3 at most): refused by prepare_grid, after the checks up front.
  const Scene s = scene({"render.levels=4"});
  EXPECT_THROW(animate(s, options()), ParameterError);
  EXPECT_FALSE(fs::exists(path("frames")));
}

TEST_F(Animate, MissingFfmpegIsOneClearLine) {
  if (!openimageio_available()) GTEST_SKIP() << "a video's frames are PNGs, which need OpenImageIO (NEBULA_OPENIMAGEIO=OFF)";
  const Scene s = scene();
  AnimateOptions o = options("frames/f_%03d.png");
  o.video = path("movie.mp4");
  const std::string keep = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", path("nothing-here").c_str(), 1);
  try {
    animate(s, o);
    ADD_FAILURE() << "no error without ffmpeg";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "video");
    EXPECT_NE(std::string(e.what()).find("ffmpeg is not installed"), std::string::npos) << e.what();
  }
  setenv("PATH", keep.c_str(), 1);
  EXPECT_FALSE(fs::exists(path("frames")));
}

TEST_F(Animate, VideoIsAnMp4OfTheFrames) {
  if (find_ffmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed (scripts/install-deps.sh installs it)";
  if (!openimageio_available()) GTEST_SKIP() << "PNG frames need OpenImageIO";
  const Scene s = scene();
  AnimateOptions o = options("frames/f_%03d.png");
  o.video = path("movie.mp4");
  o.quiet = true;
  const AnimateResult r = animate(s, o);
  EXPECT_EQ(r.video, o.video);
  std::ifstream in(o.video, std::ios::binary);
  char head[12] = {};
  in.read(head, sizeof head);
  EXPECT_EQ(std::string(head + 4, 4), "ftyp");  // an ISO media file
  EXPECT_GT(fs::file_size(o.video), 200u);
}

}  // namespace
}  // namespace nebula
