// The display transform (core/display.h) changes PNGs only: the science
// formats give back their pixels bit for bit whatever the stretch, and the
// PNG's levels follow the stretch's stated properties.
#include <gtest/gtest.h>

#include <cmath>

#include "core/test_support.h"
#include "imageio/image_output.h"
#include "imageio/tone_map.h"

namespace nebula {
namespace {

class Display : public ::testing::Test, protected testing::ScratchDir {
 protected:
  Display() : ScratchDir("nebula_display") {}
};

Image ramp() {
  Image image(64, 8, {"B", "V", "R"});
  for (int b = 0; b < 3; ++b)
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) image.at(b, x, y) = float(std::pow(10.0, -4.0 + 4.0 * x / 63.0) * (1 + b));
  return image;
}

DisplaySettings stretched() {
  DisplaySettings d;
  d.stretch = Stretch::Asinh;
  d.auto_exposure = true;
  d.percentile = 90;
  d.white = 0.8;
  d.softening = 0.01;
  return d;
}

TEST_F(Display, ScienceFormatsKeepTheirPixels) {
  const Image image = ramp();
  ImageMetadata plain, shown;
  plain.exposure = shown.exposure = 0.5;
  shown.display = stretched();
  std::vector<std::string> formats = {".h5", ".fits"};
  if (openimageio_available()) formats.push_back(".exr");
  for (const std::string& ext : formats) {
    write_image(image, path("plain" + ext), plain, false);
    write_image(image, path("shown" + ext), shown, false);
    ImageMetadata m;
    const Image a = read_image(path("plain" + ext)), b = read_image(path("shown" + ext), &m);
    EXPECT_EQ(a.pixels, image.pixels) << ext;
    EXPECT_EQ(b.pixels, image.pixels) << ext;
    EXPECT_EQ(m.exposure, 0.5) << ext;  // the camera's, not the auto exposure
  }
}

TEST(DisplayCurve, StretchesAreZeroAtZeroOneAtWhiteAndMonotone) {
  for (Stretch s : {Stretch::Linear, Stretch::Asinh, Stretch::Log}) {
    DisplaySettings d;
    d.stretch = s;
    d.white = 2.0;
    EXPECT_EQ(stretch_value(0, d), 0.0);
    EXPECT_NEAR(stretch_value(2.0, d), 1.0, 1e-12) << to_string(s);
    EXPECT_EQ(stretch_value(50.0, d), 1.0) << to_string(s);
    EXPECT_EQ(stretch_value(std::nan(""), d), 0.0);
    double previous = 0;
    for (int i = 1; i <= 1000; ++i) {
      const double y = stretch_value(2.0 * i / 1000.0, d);
      EXPECT_GT(y, previous) << to_string(s) << " " << i;
      previous = y;
    }
  }
  // asinh and log lift the faint end above the linear line: 1% of white shows far brighter.
  DisplaySettings linear, asinh, log;
  asinh.stretch = Stretch::Asinh;
  log.stretch = Stretch::Log;
  EXPECT_GT(stretch_value(0.01, asinh), 5 * stretch_value(0.01, linear));
  EXPECT_GT(stretch_value(0.01, log), 5 * stretch_value(0.01, linear));
  // The default is the former tone curve exactly.
  for (float v : {0.0f, 1e-5f, 0.01f, 0.3f, 0.99f, 1.0f, 7.0f}) EXPECT_EQ(display_level(v, 1.3, linear), srgb_level(v, 1.3));
}

TEST(DisplayCurve, AutoExposurePutsThePercentileAtWhite) {
  std::vector<float> values(1000);
  for (int i = 0; i < 1000; ++i) values[size_t(i)] = float(i + 1);  // 1 .. 1000, plus zeros ignored
  values.push_back(0.0f);
  DisplaySettings d;
  d.percentile = 90;
  d.white = 0.5;
  const double e = auto_exposure_of(values, d, 7.0);
  EXPECT_NEAR(900.0 * e, 0.5, 0.5 * 2e-3);  // the 90th percentile of 1..1000 is 900 (to one rank)
  EXPECT_EQ(auto_exposure_of({0.0f, -1.0f}, d, 7.0), 7.0);  // nothing positive: the fallback
}

TEST_F(Display, PngShowsTheStretch) {
  if (!openimageio_available()) GTEST_SKIP() << "PNG needs OpenImageIO";
  const Image image = ramp();
  ImageMetadata plain, shown;
  plain.exposure = shown.exposure = 0.5;
  shown.display = stretched();
  write_image(image, path("plain.png"), plain, false);
  write_image(image, path("shown.png"), shown, false);
  const Image a = read_any_image(path("plain.png")), b = read_any_image(path("shown.png"));
  ASSERT_EQ(a.width, 64);
  // Channel 0 is red, from band R. The faint end is brighter under asinh with auto exposure.
  EXPECT_GT(b.at(0, 8, 0), a.at(0, 8, 0) + 0.05f);
  // Auto exposure: the brightest 10% of the shown values saturate, about 10% of the pixels in red, and fewer in blue.
  int saturated = 0;
  for (int x = 0; x < 64; ++x) saturated += b.at(0, x, 0) >= 1.0f ? 1 : 0;
  EXPECT_GE(saturated, 10);
  EXPECT_LE(saturated, 30);
  EXPECT_LT(b.at(2, 40, 0), 1.0f);
}

}  // namespace
}  // namespace nebula
