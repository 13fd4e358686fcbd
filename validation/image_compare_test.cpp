#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/philox.h"
#include "validation/image_compare.h"

namespace nebula {
namespace {

Image ramp(int w, int h) {
  Image im(w, h, {"B", "V"});
  for (int b = 0; b < 2; ++b)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) im.at(b, x, y) = 1.0f + x + 2 * y + b;
  return im;
}

TEST(ImageCompare, IdenticalImagesHaveNoError) {
  const Image a = ramp(8, 6);
  const Comparison c = compare_images(a, a, nullptr, nullptr);
  ASSERT_EQ(c.bands.size(), 2u);
  EXPECT_EQ(c.bands[0].signal_pixels, 48u);
  EXPECT_EQ(c.bands[0].rel_l1, 0.0);
  EXPECT_EQ(c.bands[0].rel_l2, 0.0);
  EXPECT_EQ(c.bands[0].bias, 0.0);
  EXPECT_FALSE(c.bands[0].has_variance);
}

TEST(ImageCompare, ScaledImageHasThatBiasAndError) {
  const Image b = ramp(8, 6);
  Image a = b;
  for (float& v : a.pixels) v *= 1.1f;
  const BandComparison r = compare_images(a, b, nullptr, nullptr).bands[1];
  EXPECT_NEAR(r.rel_l1, 0.1, 1e-6);
  EXPECT_NEAR(r.rel_l2, 0.1, 1e-6);
  EXPECT_NEAR(r.bias, 0.1, 1e-6);
  EXPECT_NEAR(r.worst_1pct, 0.1, 1e-6);
}

TEST(ImageCompare, PixelsWithoutSignalAreLeftOut) {
  Image b = ramp(4, 4), a = b;
  b.at(0, 0, 0) = 0.0f;
  a.at(0, 0, 0) = 5.0f;  // error where the reference has no signal: not counted
  const BandComparison r = compare_images(a, b, nullptr, nullptr).bands[0];
  EXPECT_EQ(r.signal_pixels, 15u);
  EXPECT_EQ(r.rel_l1, 0.0);
}

// Gaussian noise of the stated variance is within the noise; a 10 sigma
// offset is not.
TEST(ImageCompare, NoiseOfTheStatedVarianceIsWithinNoise) {
  const Image b = ramp(64, 64);
  Image a = b, var = b, shifted = b;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const Uniform4 u = philox_uniform4(9, 0, uint32_t(i), 0, 0);
    const double gauss = std::sqrt(-2 * std::log(u.u0)) * std::cos(2 * 3.14159265358979 * u.u1);
    const double sigma = 0.01 * b.pixels[i];
    var.pixels[i] = float(sigma * sigma);
    a.pixels[i] = float(b.pixels[i] + sigma * gauss);
    shifted.pixels[i] = float(b.pixels[i] + 10 * sigma);
  }
  const BandComparison r = compare_images(a, b, nullptr, &var).bands[0];
  EXPECT_TRUE(r.within_noise) << r.mean_z2;
  EXPECT_NEAR(r.rel_l2, r.noise_rel_l2, 0.1 * r.noise_rel_l2);
  EXPECT_LT(r.rel_l2_excess, 0.5 * r.noise_rel_l2);
  const BandComparison s = compare_images(shifted, b, nullptr, &var).bands[0];
  EXPECT_FALSE(s.within_noise);
  EXPECT_GT(s.beyond_4sigma, 0.99);
  const std::string json = to_json(compare_images(a, b, nullptr, &var));
  EXPECT_NE(json.find("\"within_noise\": true"), std::string::npos);
}

TEST(ImageCompare, RefusesImagesThatDiffer) {
  const Image a = ramp(4, 4), b = ramp(4, 5);
  EXPECT_THROW(compare_images(a, b, nullptr, nullptr), Error);
  Image c(4, 4, {"B", "R"});
  EXPECT_THROW(compare_images(a, c, nullptr, nullptr), Error);
}

TEST(ImageCompare, DifferencePictureAndVariancePath) {
  const Image b = ramp(4, 3);
  Image a = b;
  a.at(0, 1, 1) += 2.0f;
  std::vector<double> ranges;
  const Image p = difference_picture(a, b, 1e-3, &ranges);
  EXPECT_EQ(p.width, 8);
  EXPECT_EQ(p.height, 3);
  EXPECT_EQ(p.bands, (std::vector<std::string>{"B", "V", "R"}));
  EXPECT_FLOAT_EQ(p.at(2, 1, 1), 1.0f);  // red
  EXPECT_LT(p.at(0, 1, 1), 0.5f);
  EXPECT_FLOAT_EQ(p.at(0, 0, 0), 1.0f);  // white where equal
}

}  // namespace
}  // namespace nebula
