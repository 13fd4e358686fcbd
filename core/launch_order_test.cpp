#include "core/launch_order.h"

#include <gtest/gtest.h>

#include <vector>

namespace nebula {
namespace {

// Every tile once, for every centre (and centres outside, clamped).
TEST(CentreOut, IsAPermutationForEveryCentre) {
  for (int n = 1; n <= 40; ++n)
    for (int c = -2; c < n + 2; ++c) {
      std::vector<int> seen(size_t(n), 0);
      for (int j = 0; j < n; ++j) {
        const int t = centre_out(j, c, n);
        ASSERT_GE(t, 0) << "n " << n << " c " << c << " j " << j;
        ASSERT_LT(t, n) << "n " << n << " c " << c << " j " << j;
        ++seen[size_t(t)];
      }
      for (int t = 0; t < n; ++t) EXPECT_EQ(seen[size_t(t)], 1) << "n " << n << " c " << c << " tile " << t;
    }
}

// Nearest first: the j-th tile lies no farther from the centre than the next.
TEST(CentreOut, StartsAtTheCentreAndMovesOut) {
  const int n = 11;
  for (int c = 0; c < n; ++c) {
    EXPECT_EQ(centre_out(0, c, n), c);
    for (int j = 1; j < n; ++j) {
      const int a = centre_out(j - 1, c, n) - c, b = centre_out(j, c, n) - c;
      EXPECT_LE(a < 0 ? -a : a, b < 0 ? -b : b) << "c " << c << " j " << j;
    }
  }
  EXPECT_EQ(centre_out(1, 5, n), 4);
  EXPECT_EQ(centre_out(2, 5, n), 6);
}

}  // namespace
}  // namespace nebula
