#pragma once
// A small scene the spectral renderer's tests share: a cube of noise dust
// (tau_V per voxel up to `scale`), stars with baked depths, an oblique camera.
#include <cmath>
#include <vector>

#include "core/camera.h"
#include "core/grid.h"
#include "core/philox.h"
#include "illumination/filters.h"
#include "illumination/optical_depth_bake.h"
#include "spectral/spectral_renderer.h"

namespace nebula::spectral::testing {

// Built-in filters by name, as the spectral model takes them.
inline std::vector<std::pair<std::string, Passband>> filters(std::initializer_list<const char*> names) {
  std::vector<std::pair<std::string, Passband>> out;
  for (const char* n : names) out.push_back({n, load_filter(n)});
  return out;
}

// The largest relative error per pixel of `a` against `ref`, over the pixels
// above 1e-3 of their band's peak (the goals' "pixels with signal").
inline double worst_relative_per_band(const Image& a, const Image& ref) {
  double worst = 0;
  const size_t plane = ref.plane_size();
  for (size_t b = 0; b < ref.bands.size(); ++b) {
    double peak = 0;
    for (size_t i = 0; i < plane; ++i) peak = std::max(peak, double(ref.pixels[b * plane + i]));
    for (size_t i = 0; i < plane; ++i) {
      const double r = ref.pixels[b * plane + i];
      if (r > 1e-3 * peak) worst = std::max(worst, std::fabs(a.pixels[b * plane + i] - r) / r);
    }
  }
  return worst;
}

struct SpectralTestScene {
  DensityGrid grid;
  BakeResult bake;
  std::vector<Vec3> star_positions;
  Camera camera;
  SpectralRenderInputs inputs(const SpectralModel& m) const {
    SpectralRenderInputs in;
    in.density = &grid;
    in.model = &m;
    for (size_t k = 0; k < star_positions.size(); ++k) in.lights.push_back({star_positions[k], 100.0, &bake.tau_v[k]});
    in.camera = camera;
    // One ray per pixel: the tests compare methods pixel by pixel with the
    // double integral, which marches every wavelength, and the star pixels'
    // thousands of rays (illumination/star_pixels.h) would take most of their
    // time on the CPU. SpectralRendererGpu.AgreesWithTheCpu turns them on.
    in.star_pixels = false;
    return in;
  }
};

// Light between voxels for a scene without baking a field: per star and
// node, H = P kappa A e^(-kappa D) (1 + 0.3 kappa) with A and D smooth in the
// voxel (D up to 3), P the star's spectral power at the node's wavelength, and
// a forward peak 0.05 kappa tau_V (SpectralDiffuseLight's shapes).
inline SpectralDiffuseLight synthetic_diffuse(const SpectralTestScene& s, const SpectralModel& m) {
  SpectralDiffuseLight d;
  const size_t voxels = s.grid.shape.count();
  const size_t n = m.node_kappa.size();
  d.peak.assign(n, std::vector<float>(voxels));
  for (size_t j = 0; j < n; ++j)
    for (size_t v = 0; v < voxels; ++v) d.peak[j][v] = 0.05f * float(m.node_kappa[j]) * s.grid.tau_v[v];
  for (size_t k = 0; k < s.star_positions.size(); ++k) {
    std::vector<double> power;
    for (size_t j = 0; j < n; ++j) power.push_back(100.0 * m.stars[k].shape(m.wavelength_of_kappa(m.node_kappa[j])));
    d.node_power.push_back(power);
    d.light.emplace_back(n, std::vector<float>(voxels));
    for (size_t v = 0; v < voxels; ++v) {
      const float A = 1e-3f * (1.0f + 0.5f * std::sin(0.01f * float(v) + float(k)));
      const float D = 1.5f + 1.5f * std::cos(0.003f * float(v));
      for (size_t j = 0; j < n; ++j) {
        const float kappa = float(m.node_kappa[j]);
        d.light[k][j][v] = float(power[j]) * kappa * A * std::exp(-kappa * D) * (1.0f + 0.3f * kappa);
      }
    }
  }
  return d;
}

inline SpectralTestScene noise_scene(int n, float scale, std::vector<Vec3> stars, int width, int height) {
  SpectralTestScene s;
  s.grid.shape.nx = s.grid.shape.ny = s.grid.shape.nz = n;
  s.grid.shape.voxel = 1.0f / n;
  s.grid.shape.origin = {-0.5f, -0.5f, -0.5f};
  s.grid.tau_v.resize(s.grid.shape.count());
  for (size_t c = 0; c < s.grid.tau_v.size(); ++c) s.grid.tau_v[c] = scale * philox_uniform4(11, 0, uint32_t(c), 0, 0).u0;
  s.star_positions = std::move(stars);
  s.bake = bake_star_depths_cpu(s.grid, s.star_positions);
  CameraSettings cs;
  cs.position = {0.3f, -2.5f, -2.0f};
  cs.look_at = {0, 0, 0};
  cs.up = {0, 0, 1};
  cs.fov_deg = 40;
  cs.width = width;
  cs.height = height;
  s.camera = make_camera(cs);
  return s;
}

}  // namespace nebula::spectral::testing
