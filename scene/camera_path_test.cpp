#include "scene/camera_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/philox.h"
#include "core/test_support.h"
#include "scene/scene_file.h"

namespace nebula {
namespace {

using testing::expect_error;

CameraSettings base_camera() {
  CameraSettings c = scene_camera_defaults();
  c.width = c.height = 64;
  return c;
}

CameraKeyframe key(double t, Vec3 p, Vec3 look = {0, 0, 0}, double fov = 40) {
  CameraKeyframe k;
  k.time = t;
  k.position = p;
  k.look_at = look;
  k.up = Vec3{0, 0, 1};
  k.fov_deg = fov;
  return k;
}

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }
double distance(Vec3 a, Vec3 b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

CameraPath curved_path(PathTiming timing) {
  CameraPath path;
  path.timing = timing;
  path.keys = {key(0, {5, 0, 1}, {0, 0, 0}, 40), key(1.5, {0, 4, 2}, {0, 0.5f, 0}, 60),
               key(2, {-5, 0.5f, 0}, {0, 0, 0}, 30), key(4, {0, -6, 1}, {0.2f, 0, 0}, 45)};
  return path;
}

// The tangent (Hermite) form of the centripetal Catmull-Rom segment (Yuksel,
// Schaefer & Keyser 2011, eq. for non-uniform knots): written independently of
// the Barry-Goldman pyramid the code uses.
Vec3 hermite_reference(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, double u) {
  auto d = [](Vec3 a, Vec3 b) { return std::sqrt(distance(a, b)); };
  const double t01 = d(p0, p1), t12 = d(p1, p2), t23 = d(p2, p3);
  double out[3];
  const float* a0 = &p0.x;
  const float* a1 = &p1.x;
  const float* a2 = &p2.x;
  const float* a3 = &p3.x;
  for (int c = 0; c < 3; ++c) {
    const double m1 = t12 * ((a1[c] - a0[c]) / t01 - (a2[c] - a0[c]) / (t01 + t12) + (a2[c] - a1[c]) / t12);
    const double m2 = t12 * ((a2[c] - a1[c]) / t12 - (a3[c] - a1[c]) / (t12 + t23) + (a3[c] - a2[c]) / t23);
    const double u2 = u * u, u3 = u2 * u;
    out[c] = (2 * u3 - 3 * u2 + 1) * a1[c] + (u3 - 2 * u2 + u) * m1 + (-2 * u3 + 3 * u2) * a2[c] + (u3 - u2) * m2;
  }
  return Vec3{float(out[0]), float(out[1]), float(out[2])};
}

TEST(CameraPath, CentripetalSegmentMatchesTheTangentForm) {
  UniformStream rng(7, 0, 0, 0);
  for (int trial = 0; trial < 200; ++trial) {
    Vec3 p[4];
    for (Vec3& q : p) q = Vec3{float(4 * rng.next() - 2), float(4 * rng.next() - 2), float(4 * rng.next() - 2)};
    const double u = rng.next();
    const Vec3 got = centripetal_catmull_rom(p[0], p[1], p[2], p[3], u);
    const Vec3 want = hermite_reference(p[0], p[1], p[2], p[3], u);
    EXPECT_LT(distance(got, want), 2e-5) << "trial " << trial << " u " << u;
  }
}

TEST(CameraPath, EvenlySpacedPointsOnALineGiveALine) {
  const Vec3 a{0, 0, 0}, b{1, 2, 3}, c{2, 4, 6}, d{3, 6, 9};
  for (double u : {0.1, 0.25, 0.5, 0.9}) {
    const Vec3 got = centripetal_catmull_rom(a, b, c, d, u);
    const Vec3 want{float(1 + u), float(2 + 2 * u), float(3 + 3 * u)};
    EXPECT_LT(distance(got, want), 1e-6) << u;
  }
}

TEST(CameraPath, CoincidentPointsGiveNoNaN) {
  const Vec3 a{1, 1, 1}, b{2, 1, 1};
  for (double u : {0.0, 0.3, 1.0}) {
    const Vec3 p = centripetal_catmull_rom(a, a, b, b, u);
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    EXPECT_TRUE(same_bits(centripetal_catmull_rom(a, a, a, b, u), a));  // a segment of zero length stays put
  }
}

TEST(CameraPath, KeyTimesGiveTheKeysBitForBit) {
  const CameraPath path = curved_path(PathTiming::Keyframes);
  const CameraPathSampler sampler(path, base_camera());
  for (const CameraKeyframe& k : path.keys) {
    const CameraSettings c = sampler.at(k.time);
    EXPECT_TRUE(same_bits(c.position, k.position)) << k.time;
    EXPECT_TRUE(same_bits(c.look_at, k.look_at)) << k.time;
    EXPECT_TRUE(same_bits(c.up, k.up)) << k.time;
    EXPECT_EQ(c.fov_deg, k.fov_deg) << k.time;
    EXPECT_EQ(c.width, 64);
  }
  // Continuity: just beside a key the camera is just beside the key.
  for (const CameraKeyframe& k : path.keys) {
    const double t = k.time == path.end() ? k.time - 1e-6 : k.time + 1e-6;
    EXPECT_LT(distance(sampler.position_at(t), k.position), 1e-4) << k.time;
  }
  // Outside the path: clamped to its ends.
  EXPECT_TRUE(same_bits(sampler.position_at(-3), path.keys.front().position));
  EXPECT_TRUE(same_bits(sampler.position_at(99), path.keys.back().position));
}

TEST(CameraPath, FieldOfViewNeverOvershootsItsKeys) {
  const CameraPath path = curved_path(PathTiming::Keyframes);
  const CameraPathSampler sampler(path, base_camera());
  for (size_t s = 0; s + 1 < path.keys.size(); ++s) {
    const double lo = std::fmin(path.keys[s].fov_deg, path.keys[s + 1].fov_deg);
    const double hi = std::fmax(path.keys[s].fov_deg, path.keys[s + 1].fov_deg);
    for (int i = 0; i <= 100; ++i) {
      const double t = path.keys[s].time + (path.keys[s + 1].time - path.keys[s].time) * i / 100.0;
      const double fov = sampler.at(t).fov_deg;
      EXPECT_GE(fov, lo - 1e-9) << t;
      EXPECT_LE(fov, hi + 1e-9) << t;
    }
  }
}

TEST(CameraPath, ConstantSpeedCoversEqualDistancesInEqualTimes) {
  const CameraPath path = curved_path(PathTiming::ConstantSpeed);
  const CameraPathSampler sampler(path, base_camera());
  // The length, measured here on a much finer polyline of the same spline.
  const CameraPathSampler timed(curved_path(PathTiming::Keyframes), base_camera());
  double reference = 0;
  for (size_t s = 0; s + 1 < path.keys.size(); ++s) {
    Vec3 previous = path.keys[s].position;
    for (int i = 1; i <= 20000; ++i) {
      const double t = path.keys[s].time + (path.keys[s + 1].time - path.keys[s].time) * i / 20000.0;
      const Vec3 p = timed.position_at(t);
      reference += distance(p, previous);
      previous = p;
    }
  }
  EXPECT_NEAR(sampler.length(), reference, 1e-4 * reference);
  const int steps = 200;
  const double expected = reference / steps;
  for (int i = 0; i < steps; ++i) {
    const double t0 = path.start() + (path.end() - path.start()) * i / steps;
    const double t1 = path.start() + (path.end() - path.start()) * (i + 1) / steps;
    // A chord is shorter than its arc by a relative (k L)^2 / 24 at most; these curves bend gently.
    EXPECT_NEAR(distance(sampler.position_at(t0), sampler.position_at(t1)), expected, 2e-3 * expected) << i;
  }
  EXPECT_TRUE(same_bits(sampler.position_at(path.start()), path.keys.front().position));
  EXPECT_TRUE(same_bits(sampler.position_at(path.end()), path.keys.back().position));
}

TEST(CameraPath, IssuesNameTheKey) {
  const CameraSettings base = base_camera();
  CameraPath one;
  one.keys = {key(0, {1, 0, 0})};
  expect_error([&] { CameraPathSampler(one, base); }, {"animation.keyframes", "1 keyframe", "at least 2"});
  CameraPath backwards = curved_path(PathTiming::Keyframes);
  backwards.keys[2].time = 1.5;
  expect_error([&] { CameraPathSampler(backwards, base); }, {"animation.keyframes.2.time", "must increase"});
  CameraPath looking_at_itself = curved_path(PathTiming::Keyframes);
  looking_at_itself.keys[1].look_at = looking_at_itself.keys[1].position;
  expect_error([&] { CameraPathSampler(looking_at_itself, base); }, {"animation.keyframes.1.look_at"});
  CameraPath wide = curved_path(PathTiming::Keyframes);
  wide.keys[3].fov_deg = 180;
  expect_error([&] { CameraPathSampler(wide, base); }, {"animation.keyframes.3.fov_deg"});
}

const char* kScene = R"(
[density]
procedural = { n = 8, size_pc = 2.0 }
[[stars]]
position = [1.0, 1.0, 1.0]
luminosity_lsun = 1e3
class = "B0V"
[camera]
position = [1.0, -3.0, 1.0]
look_at = [1.0, 1.0, 1.0]
fov_deg = 35
[animation]
timing = "constant_speed"
[[animation.keyframes]]
time = 0
position = [1.0, -3.0, 1.0]
[[animation.keyframes]]
time = 2.5
position = [4.0, 1.0, 1.5]
up = [0.0, 0.1, 1.0]
fov_deg = 50
)";

TEST(CameraPathFile, KeyframesAreReadWithTheCameraAsDefaults) {
  const Scene s = load_scene_text(kScene, "path.toml", ".");
  ASSERT_TRUE(s.camera_path.has_value());
  const CameraPath& p = *s.camera_path;
  EXPECT_EQ(p.timing, PathTiming::ConstantSpeed);
  ASSERT_EQ(p.keys.size(), 2u);
  EXPECT_EQ(p.keys[0].fov_deg, 35);  // from [camera]
  EXPECT_TRUE(same_bits(p.keys[0].look_at, Vec3{1, 1, 1}));
  EXPECT_TRUE(same_bits(p.keys[0].up, Vec3{0, 0, 1}));
  EXPECT_EQ(p.keys[1].time, 2.5);
  EXPECT_EQ(p.keys[1].fov_deg, 50);
  EXPECT_TRUE(same_bits(p.keys[1].up, Vec3{0, 0.1f, 1}));
  EXPECT_FALSE(load_scene_text(kScene, "path.toml", ".", {"animation.keyframes.1.time=3"}).camera_path->keys[1].time != 3);
}

TEST(CameraPathFile, BadKeyframesAreOneLineNamingTheKey) {
  const std::string text = kScene;
  const size_t second = text.rfind("[[animation.keyframes]]");
  expect_error([&] { load_scene_text(text.substr(0, second), "one.toml", "."); },
               {"one.toml", "animation.keyframes", "at least 2"});
  expect_error([&] { load_scene_text(text, "bad.toml", ".", {"animation.keyframes.1.time=0"}); },
               {"bad.toml", "animation.keyframes.1.time", "must increase", "set by override"});
  expect_error([&] { load_scene_text(text, "bad.toml", ".", {"animation.keyframes.0.zoom=2"}); },
               {"bad.toml", "animation.keyframes.0.zoom", "unknown key"});
  expect_error([&] { load_scene_text(text, "bad.toml", ".", {"animation.keyframes.1.position=[1, 2]"}); },
               {"bad.toml", "animation.keyframes.1.position", "3 numbers"});
  expect_error([&] { load_scene_text(text, "bad.toml", ".", {"animation.timing=wobbly"}); },
               {"bad.toml", "animation.timing", "wobbly"});
  expect_error([&] { load_scene_text(text, "bad.toml", ".", {"animation.keyframes=3"}); },
               {"bad.toml", "animation.keyframes", "array of tables"});
}

}  // namespace
}  // namespace nebula
