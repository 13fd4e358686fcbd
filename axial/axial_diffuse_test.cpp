// The axial diffuse field (axial_diffuse.h): the voxelized map keeps the
// dust, energy is conserved at albedo 1, and the field turned into the
// meridian frames renders what the 3D field does on the same nebula.
#include "axial/axial_diffuse.h"

#include <gtest/gtest.h>

#include <cmath>

#include "axial/axial_bake.h"
#include "axial/axial_renderer.h"
#include "axial/axial_test_scenes.h"
#include "core/math.h"
#include "illumination/optical_depth_bake.h"
#include "raycast/renderer.h"

namespace nebula {
namespace {

using testing::thin_table;

DiffuseBand band_of(const Band& b, const ScatteringTable* table) {
  DiffuseBand d;
  static_cast<Band&>(d) = b;
  d.table = table;
  return d;
}

// The dust mass, integral of tau_v / l over the volume, of the map (rings of
// texels) and of its voxelization: equal up to the voxels' staircase, which
// the 4^3 points per voxel make small (bounded here by 1%).
TEST(AxialDiffuse, VoxelizationKeepsTheDust) {
  for (const std::string name : {"cloud", "shells", "full"}) {
    const AxialMap map = synthetic_axial_map(name, 64, 32, 0.1f, 0, 1.0f);
    double rings = 0;
    for (int ir = 0; ir < map.nr; ++ir)
      for (int ix = 0; ix < map.nx; ++ix)
        rings += map.tau_v[map.index(ix, ir)] / map.texel * kPiD * (2 * ir + 1) * std::pow(map.texel, 3);
    for (float voxel : {0.1f, 0.25f}) {
      const DensityGrid g = voxelize_axial_frame(map, voxel);
      double grid = 0;
      for (float t : g.tau_v) grid += t / voxel * std::pow(voxel, 3);
      EXPECT_NEAR(grid / rings, 1.0, 0.01) << name << " voxel " << voxel;
      EXPECT_GE(g.shape.nx * voxel, 2 * map.radius());
      EXPECT_GE(g.shape.nz * voxel, map.length());
    }
  }
}

// A star at the centre of a uniform sphere of radial tau 1 drawn on the map,
// albedo 1: all the light that interacts leaves, 1 / (4 pi) of it per unit
// solid angle by the symmetry, so the image plane integral from any side is
// power (1 - <exp(-tau)>) / (4 pi). Allowed as for the grid (raycast/
// diffuse_render_test.cpp): the stated 2% plus 4 standard errors of the
// photon sum and of the table (the tabulator's, as the renderer's tables are:
// the thin-limit one scatters 2% too much light at this texel's tau_sct);
// without the field the image must miss by more.
TEST(AxialDiffuse, ConservesEnergyAtAlbedoOne) {
  const int n = 24;
  const float texel = 0.05f, R = n * texel, tau_radial = 1.0f;
  AxialMap map;
  map.nx = 2 * n;
  map.nr = n;
  map.texel = texel;
  map.origin = {0.1f, -0.2f, 0.3f};
  map.axis = normalize(Vec3{1, 2, 2});
  map.tau_v.assign(map.count(), 0.0f);
  for (int ir = 0; ir < map.nr; ++ir)
    for (int ix = 0; ix < map.nx; ++ix)
      if (std::hypot(ix + 0.5f - n, ir + 0.5f) < n) map.tau_v[map.index(ix, ir)] = tau_radial / n;
  map.update_skip_structures();
  const Vec3 star = map.origin + R * map.axis;
  // <exp(-tau)> over directions, marching the map (Fibonacci directions).
  Vec3 p_axis, q_axis;
  orthonormal_frame(map.axis, p_axis, q_axis);
  double escape = 0;
  const int n_dirs = 2000;
  for (int i = 0; i < n_dirs; ++i) {
    const double z = 1 - (i + 0.5) * 2.0 / n_dirs, s = std::sqrt(1 - z * z), phi = i * 2.399963229728653;
    double tau = 0;
    const float step = texel / 20;
    for (float t = 0.5f * step; t < 2 * R; t += step) {
      const float x = R + float(z) * t, r = float(s) * t;
      const float fx = std::floor(x / texel), fr = std::floor(r / texel);
      if (fx < 0 || fx >= map.nx || fr >= map.nr) break;
      tau += map.tau_v[map.index(int(fx), int(fr))] / texel * step;
    }
    (void)phi;
    escape += std::exp(-tau) / n_dirs;
  }
  for (float g : {0.0f, 0.6f}) {
    double table_error = 0;
    const ScatteringTable table = testing::table_at_albedo_one(g, tau_radial / n, &table_error);
    const float power = 1000.0f;
    AxialRenderInputs in;
    in.map = &map;
    in.bands.push_back(AxialRenderBand{{"V", 1.0f, 1.0f, g}, &table});
    const std::vector<std::vector<float>> depth =
        bake_axial_star_depths(map.nx, map.nr, map.texel, map.tau_v, {R}, Backend::Cpu).tau_v;
    in.stars.push_back(BakedStar{{star, {power}}, &depth[0]});
    CameraSettings cs;
    cs.projection = Projection::Orthographic;
    const Vec3 from = normalize(0.5f * map.axis + 0.8f * p_axis);
    cs.position = star + 10.0f * from;
    cs.look_at = star;
    cs.up = map.axis;
    const int pixels = 96;
    const float width = 2.2f * R;
    cs.ortho_width = width;
    cs.width = cs.height = pixels;
    in.camera = make_camera(cs);
    in.step = 0.25f * texel;
    auto total = [&](const Image& im) {
      double sum = 0;
      for (float v : im.pixels) sum += v;
      return sum * std::pow(width / pixels, 2);
    };
    const double without = total(render_axial_cpu(in, nullptr));
    DiffuseBakeOptions o;
    o.photons = 1u << 18;
    o.cells = 16;
    AxialDiffuseStats stats;
    const DiffuseField field =
        bake_axial_diffuse(map, {band_of(in.bands[0], &table)}, {static_cast<const StarLight&>(in.stars[0])}, o,
                           Backend::Cpu, &stats);
    in.diffuse = &field;
    const double with = total(render_axial_cpu(in, nullptr));
    const double expected = power * (1 - escape) / (4 * kPiD);
    const double allowed = 0.02 + 4 * std::sqrt(1.0 / double(o.photons) + table_error * table_error);
    std::printf("g %.1f: scattered light %.4g, expected %.4g (ratio %.4f, allowed +-%.3f); without the field %.4f; "
                "bake grid %dx%dx%d, field %dx%d cells\n",
                g, with, expected, with / expected, allowed, without / expected, stats.grid.nx, stats.grid.ny,
                stats.grid.nz, field.cells.nx, field.cells.ny);
    EXPECT_NEAR(with / expected, 1.0, allowed) << "g " << g;
    EXPECT_LT(without / expected, 1.0 - allowed) << "the test must tell the field from no field";
  }
}

// The same nebula on a tilted axis, seen at 60 degrees: the light the axial
// field adds (render with it minus without) against what the 3D field adds
// to the voxelized map in the grid renderer. The two share the estimator but
// not the geometry (rings against voxels, per-sample against per-voxel eye
// directions, turned harmonics against world ones): a frame turned the wrong
// way would move the forward-scattered light to the wrong side of the star.
// Bounds from the discretisation differences of the single-scattering
// comparison (axial_renderer_test.cpp: relative L1 0.15, flux 8%).
//
// At g = 0.9 both fields carry zonal degrees to 24 about the line from the
// star (degree 3 below them, as "auto" resolves there): the axial map's are
// ring averages of the 3D cells' zonal sums, evaluated per sample about the
// same line; the grid's per voxel, at its centre. The two discretisations
// differ more at g = 0.9, where the light is peaked within some 6 degrees:
// with the harmonics alone by relative L1 0.13 and 0.17, flux +3% and +8%;
// with the zonal degrees 0.20 and 0.12, flux -9% and -4% (2026-11-27).
// Bounds there: L1 < 0.25, flux within 12%. A zonal response about a wrong
// point (the star moved to 0.3 of its distance along the axis) gives L1 0.65
// and 0.53: the test tells it.
void expect_axial_field_matches_grid_field(float g_dust, int degree, int zonal, double max_l1, double max_flux) {
  for (const std::string name : {"cloud", "shells"}) {
    testing::AxialScene s(name, 48, 16, normalize(Vec3{1, 2, 3}), 50.0f, 1.0f);
    s.table = thin_table(g_dust);
    for (auto& b : s.inputs.bands) b.g = g_dust;
    s.inputs.step = 0.25f * s.map.texel;
    s.inputs.camera = s.view(60, 48, 0);
    const StarLight star{s.inputs.stars[0].position, s.inputs.stars[0].power};
    std::vector<DiffuseBand> bands;
    for (const auto& b : s.inputs.bands) bands.push_back(band_of(b, &s.table));
    DiffuseBakeOptions o;
    o.photons = 1u << 18;
    o.cells = 24;
    o.degree = degree;
    o.zonal = zonal;
    const Image axial0 = render_axial_cpu(s.inputs, nullptr);
    const DiffuseField axial_field = bake_axial_diffuse(s.map, bands, {star}, o, Backend::Cpu);
    ASSERT_EQ(axial_field.n_zonal(), zonal > 0 ? zonal - degree : 0);
    ASSERT_EQ(axial_field.zonal_stars, zonal > 0 ? 1 : 0);
    if (zonal > 0) EXPECT_LT(length(axial_field.zonal_star[0] - star.position), 1e-4f) << "the star, in the world";
    s.inputs.diffuse = &axial_field;
    const Image axial1 = render_axial_cpu(s.inputs, nullptr);

    std::vector<std::vector<float>> emission;
    const DensityGrid grid = voxelize_axial_map(s.map, 0.5f * s.map.texel, &emission);
    const std::vector<float> depth = bake_star_depths_cpu(grid, {star.position}).tau_v[0];
    RenderInputs in;
    in.density = &grid;
    for (size_t b = 0; b < 3; ++b)
      in.bands.push_back(RenderBand{s.inputs.bands[b], &s.table, nullptr});
    in.stars.push_back(BakedStar{star, &depth});
    in.camera = s.inputs.camera;
    in.star_pixels = s.inputs.star_pixels;  // one ray per pixel, as the axial scene's
    const Image grid0 = render_cpu(in, nullptr);
    const DiffuseField grid_field = bake_diffuse(grid, bands, {star}, o, Backend::Cpu);
    in.diffuse = &grid_field;
    const Image grid1 = render_cpu(in, nullptr);

    Image a = axial1, g = grid1;
    double flux_a = 0, flux_g = 0, flux_single = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
      a.pixels[i] -= axial0.pixels[i];
      g.pixels[i] -= grid0.pixels[i];
      flux_a += a.pixels[i];
      flux_g += g.pixels[i];
      flux_single += axial0.pixels[i];
    }
    const double err = testing::relative_l1(a, g);
    std::printf("g %.1f zonal %d, %s: the field's light, axial vs grid: relative L1 %.4f, flux ratio %.4f "
                "(%.1f%% of single scattering)\n",
                g_dust, zonal, name.c_str(), err, flux_a / flux_g, 100 * flux_a / flux_single);
    EXPECT_GT(flux_a, 0.1 * flux_single) << "the scene must have a field worth testing";
    EXPECT_LT(err, max_l1) << name;
    EXPECT_NEAR(flux_a / flux_g, 1.0, max_flux) << name;
  }
}

TEST(AxialDiffuse, MatchesTheGridFieldOnTheVoxelizedMap) { expect_axial_field_matches_grid_field(0.6f, 3, 0, 0.15, 0.08); }
TEST(AxialDiffuse, ZonalDegreesMatchTheGridFieldsOnTheVoxelizedMap) {
  expect_axial_field_matches_grid_field(0.9f, 3, 24, 0.25, 0.12);
}

}  // namespace
}  // namespace nebula
