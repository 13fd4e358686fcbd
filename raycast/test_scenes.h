#pragma once
// Scenes for the renderer's tests: analytic tables and simple grids.
#include <cmath>
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/grid.h"
#include "core/philox.h"
#include "illumination/optical_depth_bake.h"
#include "montecarlo/henyey_greenstein.h"
#include "montecarlo/table_conversion.h"
#include "raycast/renderer.h"
#include "tables/scattering_table.h"

namespace nebula::testing {

// The optically thin table P = tau_sct x (bin mean of p_HG): exact for g = 0.
inline ScatteringTable thin_table(double g, int n_mu = 180, double tau_max = 2.0) {
  ScatteringTable t = ScatteringTable::make_axes(tau_max, 3, AngularBinning::UniformTheta, n_mu);
  t.g = g;
  const AngularBins bins = t.bins();
  for (int i = 0; i < t.n_tau(); ++i)
    for (int k = 0; k < n_mu; ++k)
      t.P[t.index(i, k)] = static_cast<float>(t.tau[i] * hg_bin_mean(g, bins.edge(k), bins.edge(k + 1)));
  return t;
}

// The renderer's own kind of table at albedo 1 for voxels of scattering depth
// tau_sct: the tabulator's, with a row at exactly that depth (no
// interpolation in tau). `rel_stderr` gets the relative standard error of its
// scattered total there. The thin-limit table (P = tau_sct p_HG) leaves out the
// voxel's own extinction of the light it scatters: at albedo 1 its scattered
// total is too large by about (3/4)(R/l) tau_sct = 0.47 tau_sct (3.6% at the
// energy tests' 0.078; docs/diffuse.md, "Energy").
inline ScatteringTable table_at_albedo_one(double g, double tau_sct, double* rel_stderr) {
  TabulateParams p;
  p.albedo = 1.0;
  p.g = g;
  p.tau_max = 2 * tau_sct;  // rows at 0, tau/2, tau, 3 tau/2, 2 tau
  p.tau_bins = 5;
  p.binning = AngularBinning::UniformTheta;
  p.mu_bins = 180;
  p.photons_per_row = 100000;  // the row at tau_sct gets min(32, floor(1 / tau_sct)) times more
  const Tabulation t = tabulate(p, Backend::Cpu);
  *rel_stderr = t.total_stderr[2] / t.total[2];
  return to_table(t);
}

// A cube of n^3 voxels spanning [-half, half]^3.
inline DensityGrid cube(int n, float half, float tau_v = 0.0f) {
  DensityGrid g;
  g.shape.nx = g.shape.ny = g.shape.nz = n;
  g.shape.voxel = 2 * half / n;
  g.shape.origin = {-half, -half, -half};
  g.tau_v.assign(g.shape.count(), tau_v);
  return g;
}

// Fills the voxels whose centre lies within `radius` of the origin.
inline void fill_sphere(DensityGrid& g, float radius, float tau_v) {
  for (int z = 0; z < g.shape.nz; ++z)
    for (int y = 0; y < g.shape.ny; ++y)
      for (int x = 0; x < g.shape.nx; ++x)
        if (length(g.shape.centre(x, y, z)) <= radius) g.tau_v[g.shape.index(x, y, z)] = tau_v;
}

// A cube of n^3 voxels spanning [-1, 1]^3 with tau_v uniform in [0, scale)
// (Philox noise of key `key`): the CPU-GPU comparisons' grid.
inline DensityGrid noise_cube(int n, float scale, uint64_t key) {
  DensityGrid g = cube(n, 1.0f);
  for (size_t c = 0; c < g.tau_v.size(); ++c) g.tau_v[c] = scale * philox_uniform4(key, 0, uint32_t(c), 0, 0).u0;
  return g;
}

// A perspective camera looking at the origin from below and in front, the
// CPU-GPU comparisons' view.
inline Camera oblique_camera(int width, int height) {
  CameraSettings cs;
  cs.position = {0.3f, -2.5f, -2.0f};
  cs.look_at = {0, 0, 0};
  cs.up = {0, 0, 1};
  cs.fov_deg = 50;
  cs.width = width;
  cs.height = height;
  return make_camera(cs);
}

// An orthographic camera on the -z axis looking at the origin, `width` wide;
// pixels x pixels, or pixels x height where height > 0.
inline Camera telescope(int pixels, float width, int height = 0) {
  CameraSettings s;
  s.projection = Projection::Orthographic;
  s.position = {0, 0, -10};
  s.look_at = {0, 0, 0};
  s.up = {0, 1, 0};
  s.ortho_width = width;
  s.width = pixels;
  s.height = height > 0 ? height : pixels;
  return make_camera(s);
}
// One band, one star: everything render() needs, owning the pieces.
struct OneStarScene {
  DensityGrid grid;
  ScatteringTable table;
  std::vector<float> depth;
  RenderInputs inputs;
  void finish(Vec3 star, float power, float albedo, const Camera& camera) {
    depth = bake_star_depths_cpu(grid, {star}).tau_v[0];
    inputs.density = &grid;
    inputs.bands = {RenderBand{{"V", 1.0f, albedo}, &table, nullptr}};
    inputs.stars = {BakedStar{{star, {power}}, &depth}};
    inputs.camera = camera;
  }
};

}  // namespace nebula::testing
