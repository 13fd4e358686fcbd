#include "core/frame_pool.h"

#include <gtest/gtest.h>

namespace nebula {
namespace {

TEST(FramePool, ARecycledFrameLendsItsMemoryToTheNextOfItsSize) {
  Image first = take_frame_image(64, 32, {"B", "V", "R"});
  ASSERT_EQ(first.pixels.size(), size_t(64) * 32 * 3);
  EXPECT_EQ(first.width, 64);
  EXPECT_EQ(first.bands.size(), 3u);
  first.pixels[5] = 7.0f;
  const float* memory = first.pixels.data();
  recycle_frame_image(std::move(first));
  EXPECT_TRUE(first.pixels.empty());
  const Image second = take_frame_image(64, 32, {"B", "V", "R"});
  EXPECT_EQ(second.pixels.data(), memory);  // no new allocation
  EXPECT_EQ(second.pixels.size(), size_t(64) * 32 * 3);
}

TEST(FramePool, ALargerFrameGetsMemoryOfItsSize) {
  Image small = take_frame_image(8, 8, {"V"});
  recycle_frame_image(std::move(small));
  const Image big = take_frame_image(100, 50, {"B", "V"});
  EXPECT_EQ(big.pixels.size(), size_t(100) * 50 * 2);
  EXPECT_EQ(big.height, 50);
  // A smaller frame may take the big one's memory; its size is still its own.
  Image big_copy = big;
  recycle_frame_image(std::move(big_copy));
  const Image smaller = take_frame_image(10, 10, {"V"});
  EXPECT_EQ(smaller.pixels.size(), 100u);
}

TEST(FramePool, KeepsAFewFramesAndFreesTheRest) {
  for (int i = 0; i < 5; ++i) {
    Image frame = take_frame_image(16, 16 + i, {"V"});
    recycle_frame_image(std::move(frame));
  }
  // Taking many of one size after recycling only a few cannot all come from the pool:
  // the pool never hands out one buffer twice.
  Image a = take_frame_image(16, 20, {"V"}), b = take_frame_image(16, 20, {"V"}), c = take_frame_image(16, 20, {"V"}),
        d = take_frame_image(16, 20, {"V"});
  EXPECT_NE(a.pixels.data(), b.pixels.data());
  EXPECT_NE(b.pixels.data(), c.pixels.data());
  EXPECT_NE(c.pixels.data(), d.pixels.data());
  EXPECT_NE(a.pixels.data(), d.pixels.data());
}

}  // namespace
}  // namespace nebula
