#include "animation/frame_sequence.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "core/test_support.h"

namespace nebula {
namespace {

CameraPath two_second_path() {
  CameraPath p;
  p.keys.resize(3);
  p.keys[0].time = 0;
  p.keys[1].time = 0.5;
  p.keys[2].time = 2;
  return p;
}

void expect_parameter_error(const std::function<void()>& action, const std::string& parameter,
                            const std::string& piece) {
  try {
    action();
    ADD_FAILURE() << "no error; expected one for " << parameter;
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), parameter) << e.what();
    EXPECT_NE(std::string(e.what()).find(piece), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

TEST(FramePattern, FormatsTheFrameNumberAsPrintfWould) {
  EXPECT_EQ(parse_frame_pattern("frames/frame_%04d.png").path(7), "frames/frame_0007.png");
  EXPECT_EQ(parse_frame_pattern("frames/frame_%04d.png").path(12345), "frames/frame_12345.png");
  EXPECT_EQ(parse_frame_pattern("f%d.exr").path(42), "f42.exr");
  EXPECT_EQ(parse_frame_pattern("a%%b_%3d.h5").path(7), "a%b_  7.h5");
  EXPECT_EQ(parse_frame_pattern("frames/frame_%04d.png").folder(), "frames");
  EXPECT_EQ(parse_frame_pattern("f%d.exr").folder(), ".");
  for (long long k : {0LL, 5LL, 999LL, 123456LL}) {
    char want[64];
    std::snprintf(want, sizeof want, "x/y_%06lld.fits", k);
    EXPECT_EQ(parse_frame_pattern("x/y_%06d.fits").path(k), want);
  }
}

TEST(FramePattern, RefusesPatternsWithoutOneFrameNumber) {
  expect_parameter_error([] { parse_frame_pattern("frames/frame.png"); }, "pattern", "no frame number");
  expect_parameter_error([] { parse_frame_pattern("f%d_%d.png"); }, "pattern", "two frame numbers");
  expect_parameter_error([] { parse_frame_pattern("f%s.png"); }, "pattern", "only %d");
  expect_parameter_error([] { parse_frame_pattern("f%013d.png"); }, "pattern", "12 digits");
  expect_parameter_error([] { parse_frame_pattern("run%d/f.png"); }, "pattern", "file name");
}

TEST(FramePlan, CoversThePathWithBothEnds) {
  const CameraPath p = two_second_path();
  const FramePlan all = plan_frames(p, 30, std::nullopt, std::nullopt);
  EXPECT_EQ(all.first, 0);
  EXPECT_EQ(all.last, 60);
  EXPECT_EQ(all.count(), 61);
  EXPECT_EQ(all.time(15), 0.5);  // the middle key's time, exactly
  const FramePlan part = plan_frames(p, 30, 0.5, 1.0);
  EXPECT_EQ(part.first, 15);
  EXPECT_EQ(part.last, 30);
  const FramePlan between = plan_frames(p, 30, 0.51, 0.55);
  EXPECT_EQ(between.first, 16);
  EXPECT_EQ(between.last, 16);
  const FramePlan odd = plan_frames(p, 7, std::nullopt, std::nullopt);
  EXPECT_EQ(odd.last, 14);  // 2 s x 7 fps
}

TEST(FramePlan, RetimingScalesTheKeysAboutTheFirst) {
  CameraPath p = two_second_path();
  p.keys[0].time = 1;  // 1 .. 2 s
  p.keys[1].time = 1.25;
  const CameraPath r = retime_path(p, 4.0);
  EXPECT_EQ(r.keys[0].time, 1);
  EXPECT_EQ(r.keys[1].time, 2);
  EXPECT_EQ(r.keys[2].time, 5);
  EXPECT_EQ(plan_frames(r, 10, std::nullopt, std::nullopt).count(), 41);
}

TEST(FramePlan, RefusesBadNumbersNamingThem) {
  const CameraPath p = two_second_path();
  expect_parameter_error([&] { plan_frames(p, 0, std::nullopt, std::nullopt); }, "fps", "must be in (0, 1000]");
  expect_parameter_error([&] { plan_frames(p, std::nan(""), std::nullopt, std::nullopt); }, "fps", "nan");
  expect_parameter_error([&] { plan_frames(p, 30, 3.0, std::nullopt); }, "from", "the path runs from 0 to 2 s");
  expect_parameter_error([&] { plan_frames(p, 30, std::nullopt, -1.0); }, "to", "the path runs");
  expect_parameter_error([&] { plan_frames(p, 30, 1.0, 0.5); }, "to", "before from");
  expect_parameter_error([&] { plan_frames(p, 1, 0.2, 0.7); }, "to", "no frame time");
  expect_parameter_error([&] { retime_path(p, 0.0); }, "duration", "must be > 0");
}

TEST(Ffmpeg, IsLookedUpOnThePath) {
  const char* saved = std::getenv("PATH");
  const std::string keep = saved ? saved : "";
  setenv("PATH", "/nonexistent-folder", 1);
  EXPECT_EQ(find_ffmpeg(), "");
  setenv("PATH", keep.c_str(), 1);
}

}  // namespace
}  // namespace nebula
