#pragma once
// A small scene the spectral renderer's tests share: a cube of noise dust
// (tau_V per voxel up to `scale`), stars with baked depths, an oblique camera.
#include <vector>

#include "core/camera.h"
#include "core/grid.h"
#include "core/philox.h"
#include "illumination/optical_depth_bake.h"
#include "spectral/spectral_renderer.h"

namespace nebula::spectral::testing {

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
    return in;
  }
};

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
