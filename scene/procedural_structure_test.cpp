// Issue 13's additions to the procedural recipe: faded cube faces, filaments
// (ridged noise) and the far side's boundary moved and warped.
#include <gtest/gtest.h>

#include <cmath>

#include "scene/density_sources.h"
#include "scene/scene_file.h"

namespace nebula {
namespace {

double log_spread(const DensityGrid& g) {
  double sum = 0, sum2 = 0;
  for (float v : g.tau_v) {
    const double l = std::log(double(v) + 1e-30);
    sum += l;
    sum2 += l * l;
  }
  const double n = double(g.tau_v.size());
  return std::sqrt(sum2 / n - (sum / n) * (sum / n));
}

TEST(ProceduralStructure, EdgeFadeEmptiesTheFaces) {
  ProceduralParams p;
  p.n = 32;
  p.edge_fade = 0.25;
  const DensityGrid g = procedural_nebula(p);
  ProceduralParams plain = p;
  plain.edge_fade = 0;
  const DensityGrid h = procedural_nebula(plain);
  // The face voxel's centre is at u = 0.5 / 32: S(0.0625) = 3t² − 2t³ = 0.01123 of the density there, times the other axes' factors.
  for (int y = 0; y < 32; ++y)
    for (int z = 0; z < 32; ++z) {
      const size_t i = g.shape.index(0, y, z);
      EXPECT_LE(g.tau_v[i], 0.01124f * h.tau_v[i]) << y << " " << z;
    }
  // The centre is untouched.
  EXPECT_EQ(g.tau_v[g.shape.index(16, 16, 16)], h.tau_v[h.shape.index(16, 16, 16)]);
}

TEST(ProceduralStructure, FilamentsAddContrast) {
  ProceduralParams p;
  p.n = 32;
  ProceduralParams f = p;
  f.filament_amplitude = 5;
  EXPECT_GT(log_spread(procedural_nebula(f)), 1.2 * log_spread(procedural_nebula(p)));
}

TEST(ProceduralStructure, FarSideBoundaryMovesBehindTheStarAndWarps) {
  ProceduralParams p;
  p.n = 32;
  p.noise_amplitude = 0;  // smooth: only the far side's factor differs along y
  p.shell_tau = 0;
  p.far_multiplier = 4;
  p.far_transition = 0;  // a sharp boundary
  p.bubble_offset = 0;
  ProceduralParams moved = p;
  moved.far_offset = 0.25;  // the boundary at y = 0.75 of the edge
  const DensityGrid a = procedural_nebula(p), b = procedural_nebula(moved);
  // Just beyond the star (y = 0.6): far side in a, still near side in b.
  const size_t i = a.shape.index(20, 19, 16);
  EXPECT_NEAR(a.tau_v[i] / b.tau_v[i], 4.0, 1e-5);
  // Warped: the boundary's height now differs across the cube (the ratio to the unwarped grid varies in x).
  ProceduralParams warped = moved;
  warped.far_warp = 0.3;
  const DensityGrid c = procedural_nebula(warped);
  int differ = 0;
  for (int x = 0; x < 32; ++x) {
    const size_t k = c.shape.index(x, 24, 8);
    differ += c.tau_v[k] != b.tau_v[k] ? 1 : 0;
  }
  EXPECT_GT(differ, 0);
  EXPECT_LT(differ, 32);
}

TEST(ReuseGrids, TakesTheDensityOverOnlyWhenItsTablesAreUnchanged) {
  const std::string text =
      "[density]\nprocedural = { n = 8 }\n[[stars]]\nluminosity_lsun = 1e3\nclass = \"B0V\"\n"
      "[camera]\nposition = [1, -3, 1]\nlook_at = [1, 1, 1]\n";
  Scene previous = load_scene_text(text, "s.toml", ".");
  previous.density.tau_v[0] = 123.0f;  // a mark: seen again only if the grid is taken over
  const Scene edited = load_scene_text(text, "s.toml", ".", {"dust.albedo=0.9", "stars.0.luminosity_lsun=5e3"}, &previous);
  EXPECT_EQ(edited.density.tau_v[0], 123.0f);
  EXPECT_EQ(edited.dust.albedo[0], 0.9);
  EXPECT_EQ(edited.stars[0].luminosity_lsun, 5e3);
  // Other bands: the density does not follow them (emission grids would: an [emission] table names them).
  const Scene filtered = load_scene_text(text, "s.toml", ".", {"bands=[\"U\", \"sdss_g\"]"}, &previous);
  EXPECT_EQ(filtered.density.tau_v[0], 123.0f);
  const Scene reseeded = load_scene_text(text, "s.toml", ".", {"density.procedural.seed=2"}, &previous);
  EXPECT_NE(reseeded.density.tau_v[0], 123.0f);
  const Scene scaled = load_scene_text(text, "s.toml", ".", {"density.scale=2"}, &previous);
  EXPECT_NE(scaled.density.tau_v[0], 123.0f);
}

}  // namespace
}  // namespace nebula
