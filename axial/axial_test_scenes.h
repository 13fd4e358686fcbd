#pragma once
// Axial scenes for the tests: a synthetic map on a tilted axis, a star on the
// axis, three bands with emission, and cameras at a given inclination.
#include <cmath>
#include <string>
#include <vector>

#include "axial/axial_bake.h"
#include "axial/axial_renderer.h"
#include "raycast/test_scenes.h"

namespace nebula::testing {

struct AxialScene {
  AxialMap map;
  ScatteringTable table;
  std::vector<std::vector<float>> depth;
  AxialRenderInputs inputs;

  // nx x nr texels of edge 0.1 around origin (0.3, -0.2, 0.5) along `axis`;
  // a star on the axis a third of the way along (none when star_power == 0).
  AxialScene(const std::string& name, int nx, int nr, Vec3 axis = normalize(Vec3{1, 2, 3}), float star_power = 50.0f,
             float tau_scale = 3.0f) {
    map = synthetic_axial_map(name, nx, nr, 0.1f, 3, tau_scale);
    map.origin = {0.3f, -0.2f, 0.5f};
    map.axis = axis;
    table = thin_table(0.6, 72, 10.0);
    const float ratios[3] = {1.25f, 1.0f, 0.85f};
    for (int b = 0; b < 3; ++b) inputs.bands.push_back(AxialRenderBand{{std::string(1, "BVR"[b]), ratios[b], 0.6f}, &table});
    if (star_power > 0) {
      const float xs = map.nx * map.texel / 3.0f;
      depth = bake_axial_star_depths(map.nx, map.nr, map.texel, map.tau_v, {xs}, Backend::Cpu).tau_v;
      inputs.stars.push_back(BakedStar{{map.origin + xs * map.axis, {star_power, star_power, star_power}}, &depth[0]});
    }
    inputs.map = &map;
    inputs.step_aside = false;  // run the skip code even on the full map
    // One ray per pixel: these scenes' images are a few hundred pixels, where
    // the star pixels' thousands of rays (illumination/star_pixels.h) would be
    // most of every render. The CPU = GPU tests turn them on.
    inputs.star_pixels = false;
  }

  Vec3 centre() const { return map.origin + (0.5f * map.nx * map.texel) * map.axis; }

  // A camera looking at the map's centre from `distance` (orthographic when
  // distance <= 0, from far), the view direction at `inclination_deg` from the axis.
  Camera view(double inclination_deg, int pixels, float distance = 0.0f) const {
    Vec3 p, q;
    orthonormal_frame(map.axis, p, q);
    const float i = float(inclination_deg * kPiD / 180.0);
    const Vec3 from = std::cos(i) * map.axis + std::sin(i) * p;  // towards the camera
    CameraSettings cs;
    const float size = std::hypot(map.nx * map.texel, 2.0f * map.nr * map.texel);
    if (distance <= 0) {
      cs.projection = Projection::Orthographic;
      cs.position = centre() + (3.0f * size) * from;
      cs.ortho_width = 1.1f * size;
    } else {
      cs.position = centre() + distance * from;
      cs.fov_deg = 60;
    }
    cs.look_at = centre();
    cs.up = std::fabs(std::sin(i)) < 1e-3f ? p : map.axis;
    cs.width = cs.height = pixels;
    return make_camera(cs);
  }
};

// sum |a - ref| / sum |ref| over every pixel of every band.
inline double relative_l1(const Image& a, const Image& ref) {
  double d = 0, s = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    d += std::fabs(double(a.pixels[i]) - ref.pixels[i]);
    s += std::fabs(double(ref.pixels[i]));
  }
  return d / s;
}

}  // namespace nebula::testing
