// The fast renderer on a 3D grid: bands, tables, one bake per star, the
// pyramid's coarse levels, then the frame (raycast/, multires/).
#include <algorithm>
#include <chrono>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/progress.h"
#include "diffuse/diffuse_bake.h"
#include "illumination/star_pixels.h"
#include "multires/volume_pyramid.h"
#include "pipeline/render_scene.h"
#include "pipeline/run_setup.h"
#include "pipeline/shared_diffuse.h"

namespace nebula {

using namespace pipeline_detail;

namespace {

std::string mode_of(const RenderOptions& o) {
  return o.smooth_step > 0 ? "smooth step " + to_text(o.smooth_step) + " voxel" : "exact";
}

// Exact text of a float, so equal keys mean equal inputs.
std::string exact(double v) { return to_text(v); }

// What the diffuse field's photons depend on besides the bakes: each band's
// extinction and g, the stars' powers and the field's settings.
std::string photon_key(const std::string& bake, const Scene& scene, const SceneBands& bands) {
  if (bake.empty()) return "";
  std::string key = bake + "|mode " + to_string(scene.multiple_scattering);
  const DiffuseSettings& d = scene.diffuse;
  key += "|order " + std::to_string(resolved_order(d, scene.dust.g)) + " zonal " + std::to_string(resolved_zonal(d, scene.dust.g)) + " cells " + std::to_string(d.cells) + " photons " +
         std::to_string(d.photons) + " seed " + std::to_string(d.seed);
  for (size_t b = 0; b < bands.bands.size(); ++b)
    key += "|" + bands.bands[b].name + " " + exact(bands.bands[b].extinction_ratio) + " " + exact(bands.bands[b].g);
  for (const StarLight& s : bands.stars) {
    key += "|power";
    for (float p : s.power) key += " " + exact(p);
  }
  return key;
}

// What the field depends on: its photons, and each band's albedo and table
// with the response's taper.
std::string diffuse_key(const std::string& bake, const Scene& scene, const SceneBands& bands, const RenderOptions& o) {
  std::string key = photon_key(bake, scene, bands);
  if (key.empty()) return "";
  key += "|table photons " + std::to_string(o.table_photons) + " taper " + to_string(scene.diffuse.taper);
  for (size_t b = 0; b < bands.bands.size(); ++b)
    key += "|" + bands.bands[b].name + " albedo " + exact(bands.bands[b].albedo) + " " + scene.dust.table_files[b];
  return key;
}

// Whether the scene bakes a field at all (prepare_grid's condition; a band
// has a table exactly when its albedo is above 0).
bool bakes_field(const Scene& scene, const SceneBands& bands) {
  if (scene.axial || scene.multiple_scattering != MultipleScattering::Diffuse || bands.stars.empty()) return false;
  for (const Band& b : bands.bands)
    if (b.albedo > 0) return true;
  return false;
}

}  // namespace

DiffuseKeys diffuse_keys(const Scene& scene, const SceneBands& bands, const RenderOptions& o) {
  if (!bakes_field(scene, bands)) return {};
  const std::string bake = star_bake_key(scene, o.backend);
  return {photon_key(bake, scene, bands), diffuse_key(bake, scene, bands, o)};
}

PreparedGrid prepare_grid(const Scene& scene, const RenderOptions& o) {
  PreparedGrid none;
  return prepare_grid(scene, o, std::move(none));
}

PreparedGrid prepare_grid(const Scene& scene, const RenderOptions& o, PreparedGrid&& previous) {
  if (scene.axial) throw Error(scene.path + ": axial: an axial scene has no 3D grid (render it with render_scene)");
  validate_scene(scene);
  check_run_memory(scene, RunKind::Fast);
  const GridShape& shape = scene.density.shape;
  const int most_levels = max_pyramid_levels(shape);
  if (scene.pyramid_levels > most_levels)
    throw ParameterError("render.levels", std::to_string(scene.pyramid_levels) + " exceeds the " +
                                              std::to_string(most_levels) + " a grid of " + std::to_string(shape.nx) +
                                              "x" + std::to_string(shape.ny) + "x" + std::to_string(shape.nz) +
                                              " allows (the coarsest level keeps 2 voxels)");
  if (!(o.smooth_step == 0 || o.smooth_step >= 1e-3f))
    throw ParameterError("smooth_step", "step in voxels, at least 1e-3 (0: exact)");
  // A step longer than the grid samples nothing of it: an all-zero image.
  const int longest = std::max({shape.nx, shape.ny, shape.nz});
  if (!(o.smooth_step <= float(longest)))
    throw ParameterError("smooth_step", "is " + to_text(o.smooth_step) + "; must be at most " + std::to_string(longest) +
                                            " voxels, the grid's longest side (0: exact)");

  PreparedGrid p;
  p.scene = &scene;
  p.options = o;
  p.bands = scene_bands(scene);
  p.tables = resolve_tables(scene, {o.backend, o.table_photons, o.progress});
  const size_t n_bands = scene.bands.size();
  std::vector<bool> scatters(n_bands);
  bool any = false;
  for (size_t b = 0; b < n_bands; ++b) {
    scatters[b] = p.tables.per_band[b] != nullptr;
    any = any || scatters[b];
  }
  p.report = begin_report(scene, p.bands, "grid", o.backend, scatters);
  p.report.mode = mode_of(o);
  p.report.tables = p.tables.report;

  // Stars: one V-band depth bake each, when something scatters their light.
  std::vector<Vec3> positions;
  for (const StarLight& s : p.bands.stars) positions.push_back(s.position);
  p.bake_key = star_bake_key(scene, o.backend);
  const bool reuse_bake = !p.bake_key.empty() && p.bake_key == previous.bake_key && !previous.bake.tau_v.empty();
  if (any && !positions.empty() && reuse_bake) {
    p.bake = std::move(previous.bake);
    p.report.bake = {true, positions.size(), shape.count(), 0.0};
    p.report.bake.reused = true;
  } else if (any && !positions.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<Progress> bar;
    if (o.progress && o.backend == Backend::Cpu)
      bar = std::make_unique<Progress>("bake", uint64_t(positions.size()) * shape.ny * shape.nz);
    p.bake = bake_star_depths(scene.density, positions, o.backend, bar.get());
    if (bar) bar->finish();
    p.report.bake = {true, positions.size(), shape.count(), seconds_since(t0)};
  }

  // Light scattered between voxels: the diffuse field, baked by photons from the stars.
  const bool diffuse = scene.multiple_scattering == MultipleScattering::Diffuse && any && !positions.empty();
  p.report.multiple_scattering = to_string(scene.multiple_scattering);
  p.diffuse_key = diffuse ? diffuse_key(p.bake_key, scene, p.bands, o) : "";
  if (diffuse && !p.diffuse_key.empty() && p.diffuse_key == previous.diffuse_key) {
    p.diffuse = std::move(previous.diffuse);
    p.report.diffuse = previous.report.diffuse;
    p.report.diffuse.reused = true;
  } else if (diffuse) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<DiffuseBand> bands = diffuse_bands(p.bands, p.tables);
    const DiffuseBakeOptions options = diffuse_options(scene);
    DiffuseBakeStats stats;
    std::unique_ptr<Progress> bar = diffuse_progress(bands, options, o);
    p.diffuse = bake_diffuse(scene.density, bands, p.bands.stars, options, o.backend, &stats, bar.get());
    if (bar) bar->finish();
    p.report.diffuse = diffuse_report(bands, options, p.diffuse, 1 << p.diffuse.shift, stats, seconds_since(t0));
  }

  RenderInputs& in = p.inputs;
  in.density = &scene.density;
  for (size_t b = 0; b < n_bands; ++b) {
    Band band = p.bands.bands[b];
    if (!scatters[b]) band.albedo = 0.0f;
    in.bands.push_back(RenderBand{band, p.tables.per_band[b].get(), scene.emission.empty() ? nullptr : &scene.emission[b]});
  }
  if (any) {
    p.bake.device_tau_v.resize(p.bake.tau_v.size());  // kept with the bake: uploaded once for every frame
    for (size_t k = 0; k < positions.size(); ++k)
      in.stars.push_back(BakedStar{p.bands.stars[k], &p.bake.tau_v[k], &p.bake.device_tau_v[k]});
  }
  in.mode = MarchMode{o.smooth_step, true};
  if (diffuse) in.diffuse = &p.diffuse;
  p.pyramid = prepare_pyramid(in, scene.multiple_scattering == MultipleScattering::Pyramid ? scene.pyramid_levels : 0,
                              o.backend);
  return p;
}

Scene coarsened_scene(const Scene& scene, int levels) {
  if (scene.axial) throw Error(scene.path + ": axial: an axial scene has no 3D grid to coarsen");
  if (levels < 0) throw Error("coarsening by " + std::to_string(levels) + " levels: must be >= 0");
  levels = std::min(levels, max_pyramid_levels(scene.density.shape));  // the coarsest keeps 2 voxels
  Scene coarse = scene;
  for (int i = 0; i < levels; ++i) {
    const GridShape fine = coarse.density.shape;
    coarse.density = downsample(coarse.density);
    for (std::vector<float>& e : coarse.emission) e = downsample_edge_integral(fine, e);
  }
  coarse.diffuse.cells = std::max(1, scene.diffuse.cells >> levels);
  // 8x fewer cells per level: a quarter of the photons per level still leaves
  // each cell twice the photons (half the noise variance) of the full field's.
  coarse.diffuse.photons = std::max<uint64_t>(4096, scene.diffuse.photons >> (2 * levels));
  if (!coarse.grid_source.empty()) coarse.grid_source += "|coarsened " + std::to_string(levels);
  return coarse;
}

PreparedGrid prepare_grid(const Scene& scene, const RenderOptions& o, const PreparedGrid& previous) {
  // What is unchanged is copied (its device copies shared, not uploaded
  // again), leaving `previous` whole: another thread may still render from it.
  PreparedGrid donor;
  const SceneBands bands = scene_bands(scene);
  const std::string bake = star_bake_key(scene, o.backend);
  if (bake.empty() || bake != previous.bake_key || previous.bake.tau_v.empty())
    return prepare_grid(scene, o, std::move(donor));
  donor.bake_key = previous.bake_key;
  donor.bake.tau_v = previous.bake.tau_v;
  donor.bake.seconds = previous.bake.seconds;
  donor.bake.device_tau_v.resize(previous.bake.device_tau_v.size());
  for (size_t k = 0; k < previous.bake.device_tau_v.size(); ++k)
    donor.bake.device_tau_v[k].share(previous.bake.device_tau_v[k]);
  const std::string diffuse = scene.multiple_scattering == MultipleScattering::Diffuse
                                  ? diffuse_key(bake, scene, bands, o)
                                  : "";
  if (!diffuse.empty() && diffuse == previous.diffuse_key) {
    donor.diffuse = previous.diffuse;  // its device copy shared
    donor.diffuse_key = previous.diffuse_key;
    donor.report.diffuse = previous.report.diffuse;
  }
  return prepare_grid(scene, o, std::move(donor));
}

RenderOutput render_prepared(const PreparedGrid& p, const CameraSettings& settings, bool preview) {
  const Scene& scene = *p.scene;
  const Camera camera = make_camera(settings);
  const int k = samples_per_pixel_side(scene.samples_per_pixel);
  RenderInputs in = p.inputs;
  // The field is a member: a moved PreparedGrid's inputs still point at the old one's.
  if (in.diffuse) in.diffuse = &p.diffuse;
  in.camera = make_camera(supersampled_camera(settings, scene.samples_per_pixel));
  in.exposure = 1.0f;  // science pixels: the exposure goes in the metadata
  in.star_pixels = scene.star_pixels;
  in.mode.voxel_sources = preview;
  std::unique_ptr<Progress> bar;
  if (p.options.progress && p.options.backend == Backend::Cpu)
    bar = std::make_unique<Progress>("render", uint64_t(in.camera.height));
  in.progress = bar.get();
  PyramidResult pyramid = render_pyramid(in, p.pyramid, p.options.backend);
  if (bar) bar->finish();

  RenderOutput out;
  out.image = box_downsample(std::move(pyramid.image), k);
  out.report = p.report;
  out.report.camera = to_string(settings.projection);
  out.report.width = camera.width;
  out.report.height = camera.height;
  out.report.pyramid = pyramid.report;
  for (const PyramidLevelReport& r : pyramid.report) {
    out.report.render_seconds += r.render_seconds;
    out.report.table_clamps += r.table_clamps;
  }
  if (marches_star_pixels(in)) {
    report_star_pixels(in.camera, star_positions(in.stars), out.report);
  }
  draw_scene_stars(scene, p.bands, camera, 1.0, out.image);
  out.metadata = scene_metadata(scene, p.bands, settings, p.report.mode);
  out.metadata.entries.push_back({"pyramid_levels", scene.pyramid_levels});
  out.metadata.entries.push_back({"pixel_samples", scene.samples_per_pixel});
  out.metadata.entries.push_back({"multiple_scattering", multiple_scattering_text(out.report)});
  if (preview) out.metadata.entries.push_back({"preview", "voxel sources (raycast/voxel_sources.h)"});
  return out;
}

}  // namespace nebula
