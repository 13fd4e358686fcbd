#pragma once
// The axial marcher's kernel scene, assembled once from AxialRenderInputs for
// both backends (core/placement.h): the map, its skip structures, the tables
// and the baked depths placed on the host as they are, or uploaded for CUDA.
// Host code only.
#include "axial/axial_renderer.h"
#include "raycast/march_scene.h"
#include "tables/table_lookup.h"

namespace nebula {

// Validates `in`, then builds the scene march_axial_ray reads from placed arrays.
template <class Place>
AxialMarchScene assemble_axial_scene(const AxialRenderInputs& in, Place& place) {
  validate(in);
  const AxialMap& m = *in.map;
  AxialMarchScene scene{};
  scene.map = m.view();  // sizes, frame and tree levels; every array is placed below
  scene.map.tau_v = place.place(m.tau_v);
  for (int b = 0; b < kMaxBands; ++b)
    scene.map.emission[b] = size_t(b) < m.emission.size() ? place.place(m.emission[size_t(b)]) : nullptr;
  scene.map.height = place.place(m.height);
  scene.map.floor = place.place(m.floor);
  scene.map.tree = place.place(m.tree);
  scene.map.floor_tree = place.place(m.floor_tree);
  scene.map.distance = place.place(m.distance);
  scene.n_bands = static_cast<int>(in.bands.size());
  scene.min_transmittance = in.min_transmittance;
  scene.footprint = in.camera.footprint();
  scene.step = effective_step(in);
  scene.skip = effective_skip(in);
  for (int b = 0; b < scene.n_bands; ++b) {
    const AxialRenderBand& band = in.bands[size_t(b)];
    scene.extinction_ratio[b] = band.extinction_ratio;
    scene.albedo[b] = band.table ? band.albedo : 0.0f;
    scene.table[b] = band.table ? place_table(*band.table, place) : TableView{};
  }
  scene.stars = place_star_views(in.stars, scene.n_bands, place);
  scene.n_stars = static_cast<int>(in.stars.size());
  if (in.deform.any()) {
    AxialDeformView& d = scene.deform;
    d.colour = in.deform.colour;
    d.colour_noise = in.deform.colour_noise;
    d.inv_length = 1.0f / m.length();
    d.shape = in.deform.shape;
    if (d.shape) {
      d.d_max = in.deform.shape_noise.amplitude;
      d.shrink = 1.0f - d.d_max;  // the expression the march's 1 - d takes at d = d_max
      d.pull = place.keep(bake_shape_pull(in.deform.shape_noise, m.nx, m.texel, m.radius()));
    }
    deform_frame(m.axis, d.e1, d.e2);
  }
  if (in.diffuse && scene.n_stars > 0) {
    scene.has_diffuse = true;
    scene.diffuse = place_diffuse(*in.diffuse, place);
  }
  return scene;
}

}  // namespace nebula
