#include "pipeline/run_setup.h"

#include "core/error.h"
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

}  // namespace nebula::pipeline_detail
