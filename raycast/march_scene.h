#pragma once
// The ray marcher's kernel scene, assembled once from RenderInputs for both
// backends (core/placement.h): the CPU path places the host arrays
// themselves, the CUDA path uploads them. Host code only.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/bands.h"
#include "raycast/ray_march.h"
#include "raycast/renderer.h"
#include "tables/table_lookup.h"

namespace nebula {

// Kernel views of baked stars (this marcher's and the axial one's): position,
// the first n_bands band powers and the placed depth map.
template <class Place>
const StarView* place_star_views(const std::vector<BakedStar>& stars, int n_bands, Place& place) {
  std::vector<StarView> views(stars.size());
  for (size_t k = 0; k < stars.size(); ++k) {
    views[k].position = stars[k].position;
    for (int b = 0; b < n_bands; ++b) views[k].power[b] = stars[k].power[size_t(b)];
    views[k].depth_v = stars[k].depth_mirror ? place.place(*stars[k].depth_v, *stars[k].depth_mirror)
                                             : place.place(*stars[k].depth_v);
  }
  return place.keep(std::move(views));
}

// A kernel view of a diffuse field with its arrays placed.
template <class Place>
DiffuseView place_diffuse(const DiffuseField& field, Place& place) {
  DiffuseView v = field.view(/*without_harmonics=*/true);
  v.packed = place.place_mirrored(field.device_packed, field.packed_size(),
                                  [&]() -> const std::vector<float>& { return field.host_packed(); });
  for (size_t b = 0; b < field.n_bands() && b < size_t(kMaxBands); ++b)
    if (field.has_band(b)) v.response[b] = place.place(field.response[b], field.device_response[b]);
  return v;
}

// Validates `in`, then builds the scene march_ray reads from placed arrays.
template <class Place>
MarchScene assemble_march_scene(const RenderInputs& in, Place& place) {
  validate(in);
  MarchScene scene{};
  scene.density = {in.density->shape, place.place(in.density->tau_v, in.density->device_tau_v)};
  scene.n_bands = static_cast<int>(in.bands.size());
  scene.min_transmittance = in.min_transmittance;
  scene.footprint = in.camera.footprint();
  for (int b = 0; b < scene.n_bands; ++b) {
    const RenderBand& band = in.bands[size_t(b)];
    scene.extinction_ratio[b] = band.extinction_ratio;
    scene.albedo[b] = band.albedo;
    scene.table[b] = band.table ? place_table(*band.table, place) : TableView{};
    scene.emission[b] = band.emission ? place.place(*band.emission) : nullptr;
  }
  scene.stars = place_star_views(in.stars, scene.n_bands, place);
  scene.n_stars = static_cast<int>(in.stars.size());
  // The rays that may take chord_phase_mean (uniform-theta tables), by the
  // longest chord a voxel gives each ray (NearStarRadius).
  int n_mu = 0;
  for (int b = 0; b < scene.n_bands; ++b)
    if (scene.albedo[b] > 0.0f && scene.table[b].bins.kind == AngularBinning::UniformTheta &&
        scene.table[b].n_mu > n_mu)
      n_mu = scene.table[b].n_mu;
  scene.near_star_radius = NearStarRadius::phase(in.density->shape.voxel, n_mu);
  if (in.diffuse) {
    scene.has_diffuse = true;
    scene.diffuse = place_diffuse(*in.diffuse, place);
    scene.chord_field_radius = kChordFieldVoxels * in.density->shape.voxel;
    // Every ray crossing a chord that takes the field on the chord is a near
    // one (a table with few angle bins has a smaller phase radius), so the
    // image has no seam where the near rays end.
    if (scene.diffuse.zonal > 0)
      scene.near_star_radius.fixed = scene.chord_field_radius;
  }
  return scene;
}

}  // namespace nebula
