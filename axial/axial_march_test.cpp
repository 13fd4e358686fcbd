// The axial marcher's geometry and the exactness of every skipping mode.
#include "axial/axial_march.h"

#include <gtest/gtest.h>

#include <cstring>

#include "axial/axial_test_scenes.h"

namespace nebula {
namespace {

using testing::AxialScene;

constexpr AxialSkip kSkips[] = {AxialSkip::Empty,          AxialSkip::GlobalMax,        AxialSkip::Omega,
                                AxialSkip::OmegaMulti,     AxialSkip::Distance,         AxialSkip::ThesisOmegaMax,
                                AxialSkip::ThesisOmegaLarge, AxialSkip::ThesisOmegaMulti};

AxialView unit_map(int nx, int nr, float texel) {
  AxialView v;
  v.nx = nx;
  v.nr = nr;
  v.texel = texel;
  v.origin = {0, 0, 0};
  v.axis = {0, 0, 1};
  return v;
}

TEST(AxialCylinder, PerpendicularRayThroughTheAxis) {
  const AxialView m = unit_map(10, 4, 1.0f);  // x in [0, 10], r <= 4
  float t0, t1;
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {-10, 0, 5}, {1, 0, 0}), 0, 10, 4, t0, t1));
  EXPECT_FLOAT_EQ(t0, 6.0f);
  EXPECT_FLOAT_EQ(t1, 14.0f);
}

TEST(AxialCylinder, RayParallelToTheAxis) {
  const AxialView m = unit_map(10, 4, 1.0f);
  float t0, t1;
  // Inside the radius: the slab decides; on the axis itself; outside: a miss.
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {1, 2, -3}, {0, 0, 1}), 0, 10, 4, t0, t1));
  EXPECT_FLOAT_EQ(t0, 3.0f);
  EXPECT_FLOAT_EQ(t1, 13.0f);
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {0, 0, 20}, {0, 0, -1}), 0, 10, 4, t0, t1));
  EXPECT_FLOAT_EQ(t0, 10.0f);
  EXPECT_FLOAT_EQ(t1, 20.0f);
  EXPECT_FALSE(intersect_cylinder(axial_ray(m, {4.5f, 0, -3}, {0, 0, 1}), 0, 10, 4, t0, t1));
  // Parallel but outside the slab's direction: behind the camera.
  EXPECT_FALSE(intersect_cylinder(axial_ray(m, {0, 0, 12}, {0, 0, 1}), 0, 10, 4, t0, t1));
}

TEST(AxialCylinder, CameraInsideStartsAtZero) {
  const AxialView m = unit_map(10, 4, 1.0f);
  float t0, t1;
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {1, 0, 5}, {0, 1, 0}), 0, 10, 4, t0, t1));
  EXPECT_EQ(t0, 0.0f);
  EXPECT_NEAR(t1, std::sqrt(15.0f), 1e-6f);
  // Inside, looking along the axis.
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {0, 0, 5}, {0, 0, -1}), 0, 10, 4, t0, t1));
  EXPECT_EQ(t0, 0.0f);
  EXPECT_FLOAT_EQ(t1, 5.0f);
}

TEST(AxialCylinder, GrazingRaysGiveTinyOrNoIntervalsNeverNaN) {
  const AxialView m = unit_map(10, 4, 1.0f);
  float t0 = -1, t1 = -1;
  // Tangent at r = 4 exactly: touching is a miss (an empty interval).
  EXPECT_FALSE(intersect_cylinder(axial_ray(m, {-10, 4, 5}, {1, 0, 0}), 0, 10, 4, t0, t1));
  // Just inside: a short chord around t = 10.
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {-10, 3.999f, 5}, {1, 0, 0}), 0, 10, 4, t0, t1));
  EXPECT_LT(t1 - t0, 0.3f);
  EXPECT_NEAR(0.5f * (t0 + t1), 10.0f, 1e-3f);
  // Just outside.
  EXPECT_FALSE(intersect_cylinder(axial_ray(m, {-10, 4.001f, 5}, {1, 0, 0}), 0, 10, 4, t0, t1));
  // Through the rim of an end cap, oblique.
  const Vec3 d = normalize(Vec3{1, 0, 1});
  ASSERT_TRUE(intersect_cylinder(axial_ray(m, {-12, 0, -8}, d), 0, 10, 4, t0, t1));
  EXPECT_NEAR(t0, 8.0f * std::sqrt(2.0f), 1e-4f);   // enters through x = 0 at r = 4 (the rim)
  EXPECT_NEAR(t1, 16.0f * std::sqrt(2.0f), 1e-4f);  // leaves through the side at x = 8
  // Touching the rim from outside only: a miss.
  EXPECT_FALSE(intersect_cylinder(axial_ray(m, {-4, 0, -8}, d), 0, 10, 4, t0, t1));
}

TEST(AxialMaxTree, RangeMaximaAgreeWithAScan) {
  AxialMap m = synthetic_axial_map("lopsided", 37, 9, 1.0f);
  const AxialView v = m.view();
  for (int lo = -2; lo < 40; ++lo)
    for (int hi = lo; hi < 40; ++hi) ASSERT_EQ(v.range_max_tree(lo, hi), v.range_max_scan(lo, hi)) << lo << " " << hi;
  EXPECT_EQ(v.range_max_tree(0, 36), m.global_max);
  for (int lo = -2; lo < 40; ++lo)
    for (int hi = lo; hi < 40; ++hi) {
      int f = kAxialEmptyFloor;
      for (int i = std::max(lo, 0); i <= std::min(hi, 36); ++i) f = std::min(f, m.floor[size_t(i)]);
      ASSERT_EQ(v.range_min_floor(lo, hi), f) << lo << " " << hi;
    }
}

TEST(AxialMap, HeightMapIsTheHighestNonEmptyTexel) {
  for (const std::string& name : synthetic_axial_map_names()) {
    const AxialMap m = synthetic_axial_map(name, 40, 20, 1.0f, 2);
    for (int ix = 0; ix < m.nx; ++ix)
      for (int ir = 0; ir < m.nr; ++ir)
        if (!m.empty_at(m.index(ix, ir))) {
          EXPECT_LT(ir, m.height[size_t(ix)]) << name;
        }
    for (int ix = 0; ix < m.nx; ++ix)
      if (m.height[size_t(ix)] > 0) {
        EXPECT_FALSE(m.empty_at(m.index(ix, m.height[size_t(ix)] - 1))) << name;
        EXPECT_FALSE(m.empty_at(m.index(ix, m.floor[size_t(ix)]))) << name;
        for (int ir = 0; ir < m.floor[size_t(ix)]; ++ir) EXPECT_TRUE(m.empty_at(m.index(ix, ir))) << name;
      } else {
        EXPECT_EQ(m.floor[size_t(ix)], kAxialEmptyFloor);
      }
  }
  EXPECT_EQ(synthetic_axial_map("empty", 8, 8, 1.0f).global_max, 0);
  EXPECT_EQ(synthetic_axial_map("full", 8, 8, 1.0f).global_max, 8);
  const AxialMap thin = synthetic_axial_map("bipolar", 256, 128, 1.0f);
  size_t empty = 0;
  for (size_t i = 0; i < thin.count(); ++i) empty += thin.empty_at(i);
  EXPECT_GT(double(empty) / thin.count(), 0.9) << "the thin map is mostly empty";
}

// The two-pass transform against the definition, on maps with scattered
// texels, one texel, none, and distances beyond the cap.
TEST(AxialMap, DistanceMapIsTheChebyshevDistanceToTheNearestNonEmptyTexel) {
  auto brute = [](const AxialMap& m, int ix, int ir) {
    int best = kAxialMaxDistance;
    for (int jr = 0; jr < m.nr; ++jr)
      for (int jx = 0; jx < m.nx; ++jx)
        if (!m.empty_at(m.index(jx, jr))) best = std::min(best, std::max(std::abs(jx - ix), std::abs(jr - ir)));
    return best;
  };
  std::vector<AxialMap> maps;
  for (const std::string& name : synthetic_axial_map_names()) maps.push_back(synthetic_axial_map(name, 41, 17, 1.0f, 1));
  AxialMap dot = synthetic_axial_map("empty", 300, 7, 1.0f);  // one texel: distances up to 297 pass the cap
  dot.tau_v[dot.index(2, 5)] = 0.1f;
  dot.update_skip_structures();
  maps.push_back(dot);
  AxialMap scattered = synthetic_axial_map("empty", 23, 19, 1.0f, 1);
  uint32_t state = 12345;
  for (int k = 0; k < 9; ++k) {
    state = state * 1664525u + 1013904223u;
    scattered.emission[0][state % scattered.count()] = 1.0f;  // emission alone makes a texel non-empty
  }
  scattered.update_skip_structures();
  maps.push_back(scattered);
  for (size_t k = 0; k < maps.size(); ++k) {
    const AxialMap& m = maps[k];
    ASSERT_EQ(m.distance.size(), m.count());
    for (int ir = 0; ir < m.nr; ++ir)
      for (int ix = 0; ix < m.nx; ++ix)
        ASSERT_EQ(int(m.distance[m.index(ix, ir)]), brute(m, ix, ir)) << "map " << k << " at " << ix << ", " << ir;
  }
  EXPECT_EQ(int(dot.distance[dot.index(299, 0)]), kAxialMaxDistance);  // 297 away: capped
  EXPECT_EQ(int(dot.distance[dot.index(200, 0)]), 198);
  EXPECT_EQ(int(maps[3].distance[0]), kAxialMaxDistance);  // the empty map: no dust anywhere
}

bool identical(const Image& a, const Image& b) {
  return a.pixels.size() == b.pixels.size() &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

double peak(const Image& a) {
  double p = 0;
  for (float v : a.pixels) p = std::max(p, double(v));
  return p;
}

// Every skipping mode against the naive march: bit-identical images on the
// CPU, for every synthetic map, inclinations 0 to 90 degrees, orthographic
// and perspective cameras.
TEST(AxialSkipping, EveryModeIsBitIdenticalToTheNaiveMarch) {
  for (const std::string& name : synthetic_axial_map_names()) {
    AxialScene s(name, 48, 20);
    for (int inc = 0; inc <= 90; inc += 15) {
      for (float distance : {0.0f, 4.0f}) {
        s.inputs.camera = s.view(inc, 24, distance);
        s.inputs.skip = AxialSkip::Naive;
        const Image naive = render_axial_cpu(s.inputs, nullptr);
        for (float v : naive.pixels) ASSERT_TRUE(std::isfinite(v));
        if (name != "empty") {
          EXPECT_GT(peak(naive), 0.0) << name << " " << inc;
        }
        for (AxialSkip mode : kSkips) {
          s.inputs.skip = mode;
          EXPECT_TRUE(identical(render_axial_cpu(s.inputs, nullptr), naive))
              << name << ", inclination " << inc << ", " << (distance > 0 ? "perspective" : "orthographic") << ", "
              << to_string(mode);
        }
      }
    }
  }
}

// Hard rays: exactly parallel to the axis (a hand-made camera), through the
// axis (odd image widths put a pixel centre on it), grazing the global-max
// cylinder and the map's cylinder, and cameras inside the cylinder (on the
// axis, off it, inside the dust).
TEST(AxialSkipping, HardRaysAreBitIdenticalToo) {
  for (const std::string& name : synthetic_axial_map_names()) {
    AxialScene s(name, 48, 20, Vec3{0, 0, 1});
    std::vector<Camera> cameras;
    Camera along;
    along.projection = Projection::Orthographic;
    along.position = s.map.origin + Vec3{0, 0, 20};
    along.forward = {0, 0, -1};
    along.right = {1, 0, 0};
    along.up = {0, 1, 0};
    along.width = along.height = 25;
    along.half_width = along.half_height = s.map.radius();  // pixel centres through the axis
    cameras.push_back(along);
    // Grazing: the outermost pixel centres at exactly r = R and r = H l.
    for (float radius : {s.map.radius(), s.map.global_max * s.map.texel}) {
      Camera graze;
      graze.projection = Projection::Orthographic;
      graze.position = s.centre() + Vec3{0, -20, 0};
      graze.forward = {0, 1, 0};
      graze.right = {1, 0, 0};
      graze.up = {0, 0, 1};
      graze.width = graze.height = 25;
      graze.half_width = graze.half_height = radius / (1.0f - 1.0f / 25);
      cameras.push_back(graze);
    }
    for (Vec3 inside : {s.centre(), s.centre() + Vec3{0.4f, 0.3f, -0.7f}, s.map.origin + Vec3{0, 0, 0.05f}}) {
      for (Vec3 dir : {Vec3{0, 0, 1}, Vec3{1, 0.2f, 0.1f}, Vec3{0.3f, -0.2f, -1.0f}}) {
        CameraSettings cs;
        cs.position = inside;
        cs.look_at = inside + dir;
        cs.up = std::fabs(dir.x) + std::fabs(dir.y) > 0 ? Vec3{0, 0, 1} : Vec3{0, 1, 0};
        cs.fov_deg = 90;
        cs.width = cs.height = 15;
        cameras.push_back(make_camera(cs));
      }
    }
    CameraSettings dome;
    dome.projection = Projection::Fisheye;
    dome.position = s.centre();
    dome.look_at = s.centre() + Vec3{1, 0, 0};
    dome.width = dome.height = 21;
    cameras.push_back(make_camera(dome));
    for (size_t c = 0; c < cameras.size(); ++c) {
      s.inputs.camera = cameras[c];
      s.inputs.skip = AxialSkip::Naive;
      const Image naive = render_axial_cpu(s.inputs, nullptr);
      for (float v : naive.pixels) ASSERT_TRUE(std::isfinite(v));
      for (AxialSkip mode : kSkips) {
        s.inputs.skip = mode;
        EXPECT_TRUE(identical(render_axial_cpu(s.inputs, nullptr), naive))
            << name << ", camera " << c << ", " << to_string(mode);
      }
    }
  }
}

// The skipping modes do skip: samples visited on the thin map at 45 degrees,
// each of the project's versions of the thesis' modes no more than the one
// before it, omega_multi a small fraction of naive, and the distance mode
// fewer than global_max (whose clipping it shares) on the thin map and on the
// hollow shells. The thesis' own modes: omega_multi (which tries omega_max
// first) no more than omega_max, each fewer than naive, and omega_multi a
// small fraction of naive on the thin map.
TEST(AxialSkipping, ModesReadFewerTexels) {
  for (const std::string name : {"bipolar", "shells"}) {
    AxialScene s(name, 128, 48);
    s.inputs.camera = s.view(45, 32, 0);
    uint64_t previous = ~uint64_t(0), naive = 0, global_max = 0, thesis_max = 0;
    for (AxialSkip mode : axial_skip_modes()) {
      s.inputs.skip = mode;
      AxialRenderStats stats;
      render_axial_cpu(s.inputs, &stats);
      std::printf("%-8s %-12s %llu samples visited\n", name.c_str(), to_string(mode), (unsigned long long)stats.samples);
      if (mode == AxialSkip::Naive) naive = stats.samples;
      if (mode == AxialSkip::GlobalMax) global_max = stats.samples;
      if (mode >= AxialSkip::ThesisOmegaMax) {
        EXPECT_LT(stats.samples, naive) << name << " " << to_string(mode);
        if (mode == AxialSkip::ThesisOmegaMax) thesis_max = stats.samples;
        if (mode == AxialSkip::ThesisOmegaMulti) {
          EXPECT_LE(stats.samples, thesis_max) << name;
          if (name == std::string("bipolar")) {
            EXPECT_LT(stats.samples * 5, naive);
          }
        }
      } else if (mode == AxialSkip::Distance) {
        EXPECT_LT(stats.samples, global_max) << name;
        if (name == "bipolar") {
          EXPECT_LT(stats.samples * 10, naive);
        }
      } else {
        EXPECT_LE(stats.samples, previous) << name << " " << to_string(mode);
        previous = stats.samples;
      }
    }
    if (name == "bipolar") {
      EXPECT_LT(previous * 5, naive);
    }
  }
}

// A coarse step (larger than a texel) and a fine one: the skip arithmetic
// does not assume h < l.
TEST(AxialSkipping, ExactForCoarseAndFineSteps) {
  AxialScene s("shells", 40, 16);
  for (float step : {0.037f, 0.23f}) {
    s.inputs.step = step;
    s.inputs.camera = s.view(35, 20, 0);
    s.inputs.skip = AxialSkip::Naive;
    const Image naive = render_axial_cpu(s.inputs, nullptr);
    for (AxialSkip mode : kSkips) {
      s.inputs.skip = mode;
      EXPECT_TRUE(identical(render_axial_cpu(s.inputs, nullptr), naive)) << step << " " << to_string(mode);
    }
  }
}

}  // namespace
}  // namespace nebula
