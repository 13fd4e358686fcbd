#include "multires/image_pyramid.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/philox.h"

namespace nebula {
namespace {

Image random_image(int w, int h, uint32_t seed, float scale = 1) {
  Image im(w, h, {"B", "V"});
  for (size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = scale * philox_uniform4(seed, uint32_t(i), 1, 0, 0).u0;
  return im;
}

Image constant_image(int w, int h, float v) {
  Image im(w, h, {"B", "V"});
  std::fill(im.pixels.begin(), im.pixels.end(), v);
  return im;
}

TEST(ImagePyramid, DownAndUpKeepAConstantImageAndOddSizes) {
  const Image c = downsample_2x(constant_image(7, 5, 2.5f));
  EXPECT_EQ(c.width, 4);
  EXPECT_EQ(c.height, 3);
  for (float v : c.pixels) EXPECT_FLOAT_EQ(v, 2.5f);
  const Image u = upsample_2x(c, 7, 5);
  for (float v : u.pixels) EXPECT_FLOAT_EQ(v, 2.5f);
  EXPECT_THROW(upsample_2x(c, 9, 5), Error);
}

TEST(ImagePyramid, DownsampleIsTheMeanOfTheTwoByTwoBlock) {
  const Image f = random_image(5, 3, 4);
  const Image c = downsample_2x(f);
  EXPECT_FLOAT_EQ(c.at(1, 0, 0), (f.at(1, 0, 0) + f.at(1, 1, 0) + f.at(1, 0, 1) + f.at(1, 1, 1)) / 4);
  EXPECT_FLOAT_EQ(c.at(0, 2, 1), f.at(0, 4, 2));  // the corner block has one pixel
}

TEST(ImagePyramid, UpsamplingIsBilinearBetweenCoarsePixelCentres) {
  Image c(2, 1, {"V"});
  c.at(0, 0, 0) = 0;
  c.at(0, 1, 0) = 4;
  const Image u = upsample_2x(c, 4, 1);
  // Fine centres at coarse coordinates -0.25, 0.25, 0.75, 1.25 (clamped).
  EXPECT_FLOAT_EQ(u.at(0, 0, 0), 0);
  EXPECT_FLOAT_EQ(u.at(0, 1, 0), 1);
  EXPECT_FLOAT_EQ(u.at(0, 2, 0), 3);
  EXPECT_FLOAT_EQ(u.at(0, 3, 0), 4);
}

TEST(ImagePyramid, NoLevelsGiveLevelZeroExactly) {
  const Image i0 = random_image(9, 4, 1);
  const Image out = combine_pyramid({i0});
  EXPECT_EQ(out.pixels, i0.pixels);
}

TEST(ImagePyramid, CoarseLevelsThatAddNothingLeaveLevelZero) {
  // Each coarse level exactly the downsampled finer one: every dI_j = 0.
  std::vector<Image> levels{random_image(12, 9, 2)};
  for (int j = 1; j <= 3; ++j) levels.push_back(downsample_2x(levels.back()));
  const Image out = combine_pyramid(levels);
  for (size_t i = 0; i < out.pixels.size(); ++i) EXPECT_FLOAT_EQ(out.pixels[i], levels[0].pixels[i]);
}

TEST(ImagePyramid, ExtraLightAtEachLevelAddsUp) {
  // Level j holds down(level j-1) plus c_j everywhere: the result gains sum c_j.
  std::vector<Image> levels{random_image(16, 10, 3)};
  const float extra[] = {0, 0.5f, 0.25f, 0.125f};
  for (int j = 1; j <= 3; ++j) {
    Image next = downsample_2x(levels.back());
    for (float& v : next.pixels) v += extra[j];
    levels.push_back(next);
  }
  std::vector<Image> d;
  const Image out = combine_pyramid(levels, &d);
  ASSERT_EQ(d.size(), 4u);
  for (float v : d[2].pixels) EXPECT_NEAR(v, 0.25f, 1e-6);
  for (size_t i = 0; i < out.pixels.size(); ++i) EXPECT_NEAR(out.pixels[i], levels[0].pixels[i] + 0.875f, 1e-5);
}

TEST(ImagePyramid, TheCombinationNeverSubtractsLight) {
  // Arbitrary coarse levels, darker or brighter than the finer ones.
  std::vector<Image> levels{random_image(33, 17, 5)};
  for (int j = 1; j <= 4; ++j) {
    const Image& f = levels.back();
    levels.push_back(random_image(coarser_size(f.width), coarser_size(f.height), 10 + j, 1.5f));
  }
  const Image out = combine_pyramid(levels);
  bool some_gain = false;
  for (size_t i = 0; i < out.pixels.size(); ++i) {
    EXPECT_GE(out.pixels[i], levels[0].pixels[i]);
    some_gain = some_gain || out.pixels[i] > levels[0].pixels[i];
  }
  EXPECT_TRUE(some_gain);
}

TEST(ImagePyramid, RefusesLevelsOfTheWrongSize) {
  EXPECT_THROW(combine_pyramid({random_image(8, 8, 1), random_image(3, 4, 2)}), Error);
}

}  // namespace
}  // namespace nebula
