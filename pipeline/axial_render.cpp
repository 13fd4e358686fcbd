// The fast renderer on an axial map: the map, bands, tables (only with stars
// to scatter), one bake per star on the axis, then the frame (axial/).
#include <chrono>
#include <cmath>
#include <memory>

#include "axial/axial_bake.h"
#include "axial/axial_diffuse.h"
#include "axial/axial_renderer.h"
#include "core/error.h"
#include "core/progress.h"
#include "illumination/star_pixels.h"
#include "pipeline/axial_map_source.h"
#include "pipeline/render_scene.h"
#include "pipeline/run_setup.h"

namespace nebula {

using namespace pipeline_detail;

namespace {

// A scene's deformation keys as the renderer takes them (axial/axial_deform.h).
NoiseParams noise_params(const AxialNoiseSpec& n, const std::string& key) {
  NoiseParams p;
  if (!parse_noise_kind(n.kind, p.kind)) throw ParameterError(key + ".kind", "'" + n.kind + "' is not a noise kind");
  p.frequency = static_cast<float>(n.frequency);
  p.octaves = n.octaves;
  p.gain = static_cast<float>(n.gain);
  p.lacunarity = static_cast<float>(n.lacunarity);
  p.amplitude = static_cast<float>(n.amplitude);
  p.seed = n.seed;
  return p;
}

RenderOutput render_axial_scene(const Scene& scene, const RenderOptions& o) {
  if (o.smooth_step != 0) throw ParameterError("smooth_step", "not for axial maps (their step is axial.step_texels)");
  if (scene.multiple_scattering == MultipleScattering::Pyramid)
    throw ParameterError(scene.path + ": render.multiple_scattering",
                         "\"pyramid\" is for 3D grids; an axial map takes \"diffuse\" (the default) or \"none\"");
  validate_scene(scene);
  check_run_memory(scene, RunKind::Fast);
  const AxialSpec& spec = *scene.axial;
  const AxialSkip skip = parse_axial_skip(spec.skip, scene.path + ": axial.skip");
  (void)make_camera(scene.camera);  // the camera's errors before any work
  const size_t n_bands = scene.bands.size();

  const auto t_map = std::chrono::steady_clock::now();
  const AxialMap map = o.axial_map ? place_axial_map(scene, *o.axial_map) : build_axial_map(scene);
  AxialMapReport map_report;
  map_report.source = o.axial_map ? std::string("in memory (painted)")
                                  : spec.source + " " + (spec.source == "synthetic" ? spec.synthetic : spec.path);
  map_report.nx = map.nx;
  map_report.nr = map.nr;
  map_report.texel_pc = map.texel;
  map_report.emission_planes = map.emission.size();
  map_report.height_max = map.global_max;
  map_report.build_seconds = seconds_since(t_map);
  map_report.skip = to_string(skip);
  map_report.step_texels = spec.step_texels;
  map_report.map_bytes = map.bytes();
  const SceneBands sb = scene_bands(scene);

  // Tables only when there are stars to scatter: emission alone needs none.
  BandTables tables;
  tables.per_band.assign(n_bands, nullptr);
  if (!scene.stars.empty()) tables = resolve_tables(scene, {o.backend, o.table_photons, o.progress});
  std::vector<bool> scatters(n_bands);
  bool any = false;
  for (size_t b = 0; b < n_bands; ++b) {
    scatters[b] = tables.per_band[b] != nullptr;
    any = any || scatters[b];
  }

  RenderOutput out;
  RunReport& report = out.report;
  report = begin_report(scene, sb, "axial", o.backend, scatters);
  report.mode = std::string("axial ") + to_string(skip) + " step " + to_text(spec.step_texels) + " texel";
  if (spec.colour_deform.on) report.mode += ", colour deformation " + spec.colour_deform.kind;
  if (spec.shape_deform.on) report.mode += ", shape deformation " + spec.shape_deform.kind;
  report.tables = tables.report;

  // Stars on the axis: one 2D bake each.
  std::vector<float> star_x;
  for (const SceneStar& s : scene.stars) star_x.push_back(dot(s.position - map.origin, map.axis));
  BakeResult bake;
  if (any) {
    const auto t0 = std::chrono::steady_clock::now();
    bake = bake_axial_star_depths(map.nx, map.nr, map.texel, map.tau_v, star_x, o.backend);
    report.bake = {true, star_x.size(), map.count(), seconds_since(t0)};
  }

  // Light scattered between cells: the diffuse field, baked by photons from
  // the stars through the map voxelized in its own frame, kept on the map.
  const bool diffuse = scene.multiple_scattering == MultipleScattering::Diffuse && any && !star_x.empty();
  report.multiple_scattering = to_string(scene.multiple_scattering);
  DiffuseField field;
  if (diffuse) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<DiffuseBand> bands = diffuse_bands(sb, tables);
    const DiffuseBakeOptions options = diffuse_options(scene);
    AxialDiffuseStats stats;
    std::unique_ptr<Progress> bar = diffuse_progress(bands, options, o);
    field = bake_axial_diffuse(map, bands, sb.stars, options, o.backend, &stats, bar.get());
    if (bar) bar->finish();
    report.diffuse = diffuse_report(bands, options, field, 0, stats.bake, seconds_since(t0));
    report.diffuse.axial = true;
    report.diffuse.photon_grid = stats.grid;
  }

  AxialRenderInputs in;
  in.map = &map;
  if (diffuse) in.diffuse = &field;
  for (size_t b = 0; b < n_bands; ++b) {
    Band band = sb.bands[b];
    if (!scatters[b]) band.albedo = 0.0f;
    in.bands.push_back(AxialRenderBand{band, tables.per_band[b].get()});
  }
  if (any)
    for (size_t k = 0; k < star_x.size(); ++k) in.stars.push_back(BakedStar{sb.stars[k], &bake.tau_v[k]});
  in.camera = make_camera(supersampled_camera(scene.camera, scene.samples_per_pixel));
  in.exposure = 1.0f;  // science pixels: the exposure goes in the metadata
  in.star_pixels = scene.star_pixels;
  in.step = static_cast<float>(spec.step_texels * map.texel);
  in.skip = skip;
  in.deform.colour = spec.colour_deform.on;
  in.deform.colour_noise = noise_params(spec.colour_deform, scene.path + ": axial.colour_deform");
  in.deform.shape = spec.shape_deform.on;
  in.deform.shape_noise = noise_params(spec.shape_deform, scene.path + ": axial.shape_deform");
  AxialRenderStats stats;
  std::unique_ptr<Progress> bar;
  if (o.progress && o.backend == Backend::Cpu) bar = std::make_unique<Progress>("render", uint64_t(in.camera.height));
  in.progress = bar.get();
  out.image = box_downsample(render_axial(in, o.backend, &stats), samples_per_pixel_side(scene.samples_per_pixel));
  if (bar) bar->finish();
  for (float v : out.image.pixels)
    if (!std::isfinite(v)) throw Error("axial render: a non-finite pixel (a bug: please report the scene)");

  map_report.skip_used = to_string(stats.skip_used);
  map_report.render_bytes = stats.device_bytes;
  report.axial = map_report;
  report.render_seconds = stats.seconds;
  report.table_clamps = stats.table_clamps;
  if (in.star_pixels && !in.stars.empty()) {
    report_star_pixels(in.camera, star_positions(in.stars), report);
  }
  out.metadata = scene_metadata(scene, sb, scene.camera, report.mode);
  out.metadata.entries.push_back({"multiple_scattering", multiple_scattering_text(report)});
  out.metadata.entries.push_back({"pixel_samples", scene.samples_per_pixel});
  return out;
}

}  // namespace

RenderOutput render_scene(const Scene& scene, const RenderOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  RenderOutput out =
      scene.spectral ? render_spectral_scene(scene, options)
      : scene.axial  ? render_axial_scene(scene, options)
                     : render_prepared(prepare_grid(scene, options), scene.camera);
  out.report.total_seconds = seconds_since(start);
  return out;
}

}  // namespace nebula
