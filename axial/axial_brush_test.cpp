// Painting the axial map: the brush's footprint, set / add / erase, clamping
// to the map, the skip structures rebuilt, refused brushes.
#include "axial/axial_brush.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/test_support.h"

namespace nebula {
namespace {

AxialMap empty_map(int nx, int nr) {
  AxialMap m = synthetic_axial_map("empty", nx, nr, 0.1f, 0);
  m.update_skip_structures();
  return m;
}

size_t nonzero(const std::vector<float>& v) {
  size_t n = 0;
  for (float x : v) n += x != 0;
  return n;
}

Brush hard(BrushShape shape, float radius, float value) {
  Brush b;
  b.shape = shape;
  b.radius = radius;
  b.value = value;
  b.n_bands = 3;
  return b;
}

TEST(AxialBrush, RoundAndSquareFootprints) {
  // Centred on texel (10, 10): the lattice points within 3 of a lattice point
  // are 29 (columns of 7, 5, 5, 5, 5, 1, 1), those of a 7 x 7 square 49.
  AxialMap m = empty_map(32, 24);
  PaintResult r = paint_axial_map(m, hard(BrushShape::Round, 3, 2.0f), {{10.5f, 10.5f}});
  EXPECT_EQ(r.texels, 29u);
  EXPECT_EQ(nonzero(m.tau_v), 29u);
  EXPECT_EQ(r.x0, 7);
  EXPECT_EQ(r.x1, 13);
  EXPECT_EQ(r.r0, 7);
  EXPECT_EQ(r.r1, 13);
  EXPECT_EQ(m.tau_v[m.index(13, 10)], 2.0f);  // on the circle
  EXPECT_EQ(m.tau_v[m.index(12, 12)], 2.0f);  // d = sqrt(8) < 3
  EXPECT_EQ(m.tau_v[m.index(13, 11)], 0.0f);  // d = sqrt(10) > 3
  AxialMap s = empty_map(32, 24);
  r = paint_axial_map(s, hard(BrushShape::Square, 3, 2.0f), {{10.5f, 10.5f}});
  EXPECT_EQ(r.texels, 49u);
  EXPECT_EQ(nonzero(s.tau_v), 49u);
  EXPECT_EQ(s.tau_v[s.index(13, 13)], 2.0f);
  EXPECT_EQ(s.tau_v[s.index(14, 10)], 0.0f);
  // Below half a texel: the texel under the centre alone.
  AxialMap t = empty_map(32, 24);
  EXPECT_EQ(paint_axial_map(t, hard(BrushShape::Round, 0.2f, 1.0f), {{4.9f, 2.1f}}).texels, 1u);
  EXPECT_EQ(t.tau_v[t.index(4, 2)], 1.0f);
}

TEST(AxialBrush, SetAddEraseAndSoft) {
  AxialMap m = empty_map(32, 24);
  Brush b = hard(BrushShape::Round, 2, 0.5f);
  b.mode = BrushMode::Add;
  paint_axial_map(m, b, {{8.5f, 8.5f}, {8.5f, 8.5f}});
  EXPECT_FLOAT_EQ(m.tau_v[m.index(8, 8)], 1.0f);  // two dabs of 0.5
  b.value = -5;  // adding below zero stops at zero
  paint_axial_map(m, b, {{8.5f, 8.5f}});
  EXPECT_EQ(m.tau_v[m.index(8, 8)], 0.0f);
  EXPECT_EQ(m.empty_texels, m.count());

  // Soft set on an empty map: weight 1 - d / radius, so value * (1 - d / R).
  Brush soft = hard(BrushShape::Round, 4, 2.0f);
  soft.soft = true;
  paint_axial_map(m, soft, {{16.5f, 10.5f}});
  EXPECT_FLOAT_EQ(m.tau_v[m.index(16, 10)], 2.0f);
  EXPECT_FLOAT_EQ(m.tau_v[m.index(18, 10)], 2.0f * 0.5f);   // d = 2
  EXPECT_FLOAT_EQ(m.tau_v[m.index(19, 10)], 2.0f * 0.25f);  // d = 3
  EXPECT_EQ(m.tau_v[m.index(20, 10)], 0.0f);                // d = 4: weight 0

  // Set replaces what is there.
  paint_axial_map(m, hard(BrushShape::Square, 1, 7.0f), {{16.5f, 10.5f}});
  EXPECT_EQ(m.tau_v[m.index(16, 10)], 7.0f);
  EXPECT_EQ(m.tau_v[m.index(17, 11)], 7.0f);
}

TEST(AxialBrush, EmissionPlanesAndEraseEmptiesEveryPlane) {
  AxialMap m = empty_map(20, 10);
  Brush b = hard(BrushShape::Round, 0.4f, 3.0f);
  b.plane.band = 1;
  paint_axial_map(m, b, {{5.5f, 5.5f}});
  ASSERT_EQ(m.emission.size(), 3u);  // zero planes for every band, then band 1 painted
  EXPECT_EQ(m.emission[1][m.index(5, 5)], 3.0f);
  EXPECT_EQ(nonzero(m.emission[0]) + nonzero(m.emission[2]) + nonzero(m.tau_v), 0u);
  EXPECT_EQ(m.empty_texels, m.count() - 1);  // emission alone makes a texel non-empty

  // The full map erased by one brush over all of it: empty again, skip structures too.
  AxialMap full = synthetic_axial_map("full", 20, 10, 0.1f, 3);
  full.update_skip_structures();
  ASSERT_EQ(full.empty_texels, 0u);
  Brush erase = hard(BrushShape::Square, 30, 0);
  erase.mode = BrushMode::Erase;
  paint_axial_map(full, erase, {{10, 5}});
  EXPECT_EQ(full.empty_texels, full.count());
  EXPECT_EQ(full.global_max, 0);
  EXPECT_EQ(nonzero(full.tau_v), 0u);
  for (const auto& plane : full.emission) EXPECT_EQ(nonzero(plane), 0u);
}

TEST(AxialBrush, ClampedToTheMap) {
  AxialMap m = empty_map(16, 8);
  // At the corner: only the quarter inside the map (the 29 of a full disc would not fit).
  PaintResult r = paint_axial_map(m, hard(BrushShape::Square, 3, 1.0f), {{0.5f, 0.5f}});
  EXPECT_EQ(r.texels, 16u);  // ix, ir in 0..3
  EXPECT_EQ(r.x0, 0);
  EXPECT_EQ(r.r0, 0);
  EXPECT_EQ(r.x1, 3);
  EXPECT_EQ(r.r1, 3);
  r = paint_axial_map(m, hard(BrushShape::Square, 3, 1.0f), {{15.5f, 7.5f}});
  EXPECT_EQ(r.texels, 16u);  // ix 12..15, ir 4..7
  EXPECT_EQ(nonzero(m.tau_v), 32u);
  // Wholly outside: nothing.
  r = paint_axial_map(m, hard(BrushShape::Round, 2, 1.0f), {{-10, 3}, {40, 3}, {5, -9}, {5, 30}});
  EXPECT_EQ(r.texels, 0u);
  EXPECT_EQ(nonzero(m.tau_v), 32u);
}

TEST(AxialBrush, SkipStructuresRebuilt) {
  AxialMap m = empty_map(24, 12);
  ASSERT_EQ(m.global_max, 0);
  paint_axial_map(m, hard(BrushShape::Round, 0.3f, 1.0f), {{5.5f, 3.5f}});
  EXPECT_EQ(m.height[5], 4);  // 1 + the highest non-empty r index
  EXPECT_EQ(m.floor[5], 3);
  EXPECT_EQ(m.height[6], 0);
  EXPECT_EQ(m.floor[6], kAxialEmptyFloor);
  EXPECT_EQ(m.global_max, 4);
  EXPECT_EQ(m.view().range_max_tree(0, 23), 4);
  EXPECT_EQ(m.view().range_min_floor(4, 6), 3);
  EXPECT_EQ(m.distance[m.index(5, 3)], 0);
  EXPECT_EQ(m.distance[m.index(8, 3)], 3);  // Chebyshev distance to the painted texel
  EXPECT_EQ(m.distance[m.index(7, 9)], 6);
  EXPECT_EQ(m.empty_texels, m.count() - 1);
}

TEST(AxialBrush, RefusedBrushesEditNothing) {
  AxialMap m = empty_map(16, 8);
  const std::vector<float> before = m.tau_v;
  Brush b = hard(BrushShape::Round, 2, 1.0f);
  b.plane.band = 3;  // the scene has 3 bands: 0..2
  testing::expect_error([&] { paint_axial_map(m, b, {{4, 4}}); }, {"brush: plane", "band 3"});
  b = hard(BrushShape::Round, 0, 1.0f);
  testing::expect_error([&] { paint_axial_map(m, b, {{4, 4}}); }, {"brush: radius"});
  b = hard(BrushShape::Round, 2, -1.0f);
  testing::expect_error([&] { paint_axial_map(m, b, {{4, 4}}); }, {"brush: value", ">= 0"});
  b = hard(BrushShape::Round, 2, 1.0f);
  testing::expect_error([&] { paint_axial_map(m, b, {{std::nanf(""), 4}}); }, {"brush: a dab"});
  EXPECT_EQ(m.tau_v, before);
  EXPECT_TRUE(m.emission.empty());
}

TEST(AxialBrush, SegmentWithoutGaps) {
  const std::vector<BrushPoint> d = brush_segment({0, 0}, {10, 0}, 4);
  ASSERT_EQ(d.size(), 10u);  // spaced radius / 4 = 1 texel
  EXPECT_FLOAT_EQ(d.front().x, 1);
  EXPECT_FLOAT_EQ(d.back().x, 10);
  EXPECT_EQ(brush_segment({3, 3}, {3, 3}, 2).size(), 1u);
  EXPECT_EQ(brush_segment({0, 0}, {0, 1}, 0.1f).size(), 4u);  // at least a quarter texel apart
}

}  // namespace
}  // namespace nebula
