#include "core/dda.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/philox.h"

namespace nebula {
namespace {

GridShape shape(int n, float voxel = 1.0f, Vec3 origin = {0, 0, 0}) {
  GridShape g;
  g.nx = g.ny = g.nz = n;
  g.voxel = voxel;
  g.origin = origin;
  return g;
}

// Length of segment a -> b inside the box, by slab clipping in double: an
// independent route to what the traversal's lengths must add up to.
double clipped_length(const GridShape& g, Vec3 a, Vec3 b) {
  const double p[3] = {a.x, a.y, a.z}, q[3] = {b.x, b.y, b.z};
  const double lo[3] = {g.origin.x, g.origin.y, g.origin.z};
  const double hi[3] = {lo[0] + g.voxel * g.nx, lo[1] + g.voxel * g.ny, lo[2] + g.voxel * g.nz};
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    const double d = q[k] - p[k];
    if (d == 0) {
      if (p[k] < lo[k] || p[k] > hi[k]) return 0;
      continue;
    }
    double ta = (lo[k] - p[k]) / d, tb = (hi[k] - p[k]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 >= t1) return 0;
  const double len = std::sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                               (q[2] - p[2]) * (q[2] - p[2]));
  return (t1 - t0) * len;
}

Vec3 random_point(uint32_t i, uint32_t k, float lo, float hi) {
  const Uniform4 u = philox_uniform4(77, k, i, 0, 0);
  return {lo + (hi - lo) * u.u0, lo + (hi - lo) * u.u1, lo + (hi - lo) * u.u2};
}

TEST(Dda, LengthsAddUpToTheClippedSegment) {
  const GridShape g = shape(16, 0.5f, {-1, -2, 0.25f});
  for (uint32_t i = 0; i < 2000; ++i) {
    const Vec3 a = random_point(i, 0, -6, 10), b = random_point(i, 1, -6, 10);
    double sum = 0;
    int visits = 0;
    size_t last = size_t(-1);
    traverse_segment(g, a, b, [&](size_t cell, float chord) {
      EXPECT_LT(cell, g.count());
      EXPECT_GE(chord, 0.0f);
      EXPECT_NE(cell, last);  // each voxel once, in order
      last = cell;
      sum += chord;
      ++visits;
    });
    const double expected = clipped_length(g, a, b);
    EXPECT_NEAR(sum, expected, 1e-5 * (1 + expected)) << "segment " << i;
    EXPECT_LE(visits, 3 * 16 + 3);
  }
}

// Against midpoint quadrature of the density along the segment: each voxel
// boundary can misattribute at most one quadrature step of density.
TEST(Dda, OpticalDepthMatchesQuadrature) {
  DensityGrid grid;
  grid.shape = shape(12, 1.0f);
  grid.tau_v.resize(grid.shape.count());
  for (size_t c = 0; c < grid.tau_v.size(); ++c)
    grid.tau_v[c] = 3.0f * philox_uniform4(5, 0, uint32_t(c), 0, 0).u0;
  const int steps = 200000;
  for (uint32_t i = 0; i < 50; ++i) {
    const Vec3 a = random_point(i, 2, -2, 14), b = random_point(i, 3, -2, 14);
    const float dda = segment_optical_depth(grid.view(), a, b);
    double quad = 0;
    const Vec3 d = b - a;
    const double ds = length(d) / steps;
    for (int s = 0; s < steps; ++s) {
      const Vec3 p = a + ((s + 0.5f) / steps) * d;
      const int x = int(std::floor(p.x)), y = int(std::floor(p.y)), z = int(std::floor(p.z));
      if (x < 0 || y < 0 || z < 0 || x >= 12 || y >= 12 || z >= 12) continue;
      quad += grid.tau_v[grid.shape.index(x, y, z)] * ds;
    }
    const double bound = (3 * 12 + 2) * ds * 3.0 + 1e-5 * quad;
    EXPECT_NEAR(dda, quad, bound) << "segment " << i;
  }
}

TEST(Dda, HardSegments) {
  DensityGrid grid;
  grid.shape = shape(4);
  grid.tau_v.assign(grid.shape.count(), 1.0f);
  const DensityView v = grid.view();
  // Along a grid line and along a face: the whole length counts once.
  EXPECT_NEAR(segment_optical_depth(v, {0, 1, 1}, {4, 1, 1}), 4.0f, 1e-5f);
  EXPECT_NEAR(segment_optical_depth(v, {2, 0, 0}, {2, 4, 0}), 4.0f, 1e-5f);
  // Through a corner, along the main diagonal.
  EXPECT_NEAR(segment_optical_depth(v, {0, 0, 0}, {4, 4, 4}), 4.0f * std::sqrt(3.0f), 1e-4f);
  // Beyond the grid on both ends, backwards.
  EXPECT_NEAR(segment_optical_depth(v, {9, 0.5f, 0.5f}, {-5, 0.5f, 0.5f}), 4.0f, 1e-5f);
  // Zero length, outside, parallel outside, ending mid-voxel.
  EXPECT_EQ(segment_optical_depth(v, {1, 1, 1}, {1, 1, 1}), 0.0f);
  EXPECT_EQ(segment_optical_depth(v, {5, 5, 5}, {9, 9, 9}), 0.0f);
  EXPECT_EQ(segment_optical_depth(v, {-1, 0.5f, 0.5f}, {-1, 3.5f, 0.5f}), 0.0f);
  EXPECT_NEAR(segment_optical_depth(v, {0.5f, 0.5f, 0.5f}, {2.25f, 0.5f, 0.5f}), 1.75f, 1e-6f);
}

}  // namespace
}  // namespace nebula
