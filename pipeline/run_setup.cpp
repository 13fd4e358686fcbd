#include "pipeline/run_setup.h"

#include "core/error.h"
#include "core/progress.h"
#include "pipeline/render_scene.h"
#include "raycast/point_stars.h"

namespace nebula::pipeline_detail {

RunReport begin_report(const Scene& scene, const SceneBands& bands, const std::string& renderer, Backend backend,
                       const std::vector<bool>& scatters) {
  RunReport r;
  r.scene = scene.path;
  r.renderer = renderer;
  r.backend = backend;
  r.camera = to_string(scene.camera.projection);
  r.width = scene.camera.width;
  r.height = scene.camera.height;
  r.grid = scene.density.shape;
  r.stars = scene.stars.size();
  r.R_V = scene.dust.R_V;
  r.law = scene.dust.law;
  r.emission = !scene.emission.empty();
  for (size_t b = 0; b < bands.bands.size(); ++b) {
    const Band& band = bands.bands[b];
    r.bands.push_back({band.name, band.extinction_ratio, scene.dust.albedo[b], scene.dust.g[b],
                       scatters.empty() ? band.albedo > 0 : bool(scatters[b])});
  }
  return r;
}

ImageMetadata scene_metadata(const Scene& scene, const SceneBands& bands, const CameraSettings& camera,
                             const std::string& mode) {
  ImageMetadata meta;
  meta.units = "L_sun pc^-2 sr^-1 x exposure";
  meta.exposure = 1.0;  // the camera exposure is already in the pixels
  for (size_t b = 0; b < scene.bands.size(); ++b) {
    meta.entries.push_back({"albedo_" + scene.bands[b], to_text(scene.dust.albedo[b])});
    meta.entries.push_back({"g_" + scene.bands[b], to_text(scene.dust.g[b])});
    meta.entries.push_back({"ext_" + scene.bands[b], to_text(bands.bands[b].extinction_ratio)});
  }
  meta.entries.push_back({"R_V", to_text(scene.dust.R_V)});
  meta.entries.push_back({"camera", std::string(to_string(camera.projection)) + " " +
                                        std::to_string(camera.width) + "x" + std::to_string(camera.height)});
  meta.entries.push_back({"scene", scene.path});
  meta.entries.push_back({"mode", mode});
  return meta;
}

void draw_scene_stars(const Scene& scene, const SceneBands& bands, const Camera& camera, double exposure,
                      Image& image) {
  if (!scene.draw_stars) return;
  std::vector<float> ratios;
  for (const Band& b : bands.bands) ratios.push_back(b.extinction_ratio);
  draw_point_stars(scene.density, bands.stars, ratios, camera, static_cast<float>(exposure), scene.star_psf_pixels,
                   image);
}

// What the image's light between voxels came from, for its metadata.
std::string multiple_scattering_text(const RunReport& r) {
  if (r.diffuse.done)
    return std::string(r.diffuse.axial ? "axial " : "") + "diffuse order " + std::to_string(r.diffuse.order) + ", " + std::to_string(r.diffuse.cells.nx) + "x" +
           std::to_string(r.diffuse.cells.ny) + "x" + std::to_string(r.diffuse.cells.nz) + " cells, " +
           std::to_string(r.diffuse.photons_per_band) + " photons per band";
  if (r.multiple_scattering == "pyramid") return "pyramid " + std::to_string(r.pyramid.size() - 1) + " levels";
  return r.multiple_scattering == "diffuse" ? "none (nothing scatters starlight)" : "none";
}

std::vector<DiffuseBand> diffuse_bands(const SceneBands& bands, const BandTables& tables) {
  std::vector<DiffuseBand> out;
  for (size_t b = 0; b < bands.bands.size(); ++b) {
    DiffuseBand band;
    static_cast<Band&>(band) = bands.bands[b];
    band.table = tables.per_band[b].get();
    if (!band.table) band.albedo = 0.0f;
    out.push_back(band);
  }
  return out;
}

DiffuseBakeOptions diffuse_options(const Scene& scene) {
  DiffuseBakeOptions options;
  options.degree = scene.diffuse.order;
  options.cells = scene.diffuse.cells;
  options.photons = scene.diffuse.photons;
  options.seed = scene.diffuse.seed;
  return options;
}

DiffuseReport diffuse_report(const std::vector<DiffuseBand>& bands, const DiffuseBakeOptions& options,
                             const DiffuseField& field, int voxels_per_cell, const DiffuseBakeStats& stats,
                             double wall_seconds) {
  DiffuseReport r;
  r.done = true;
  r.order = options.degree;
  r.cells = field.cells;
  r.voxels_per_cell = voxels_per_cell;
  r.photons_per_band = options.photons;
  for (const DiffuseBand& b : bands) r.bands += b.albedo > 0;
  r.seconds = stats.seconds;
  r.wall_seconds = wall_seconds;
  r.noise = stats.noise;
  r.collisions = stats.counters.collisions;
  r.crossings = stats.counters.crossings;
  r.capped = stats.counters.capped;
  r.field_bytes = stats.field_bytes;
  r.work_bytes = stats.work_bytes;
  return r;
}

std::unique_ptr<Progress> diffuse_progress(const std::vector<DiffuseBand>& bands, const DiffuseBakeOptions& options,
                                           const RenderOptions& o) {
  if (!o.progress || o.backend != Backend::Cpu) return nullptr;
  size_t baked = 0;
  for (const DiffuseBand& b : bands) baked += b.albedo > 0;
  return std::make_unique<Progress>("diffuse", options.photons * baked);
}

}  // namespace nebula::pipeline_detail
