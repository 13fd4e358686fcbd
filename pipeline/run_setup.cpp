#include "pipeline/run_setup.h"

#include <cmath>
#include <ctime>

#include "core/error.h"
#include "illumination/passband.h"
#include "core/progress.h"
#include "illumination/star_pixels.h"
#include "pipeline/render_scene.h"
#include "raycast/point_stars.h"

namespace nebula::pipeline_detail {

std::string star_bake_key(const Scene& scene, Backend backend) {
  if (scene.grid_source.empty()) return "";
  std::string key = scene.grid_source + "|backend " + std::to_string(int(backend)) + "|stars";
  for (const SceneStar& s : scene.stars)
    key += " " + to_text(s.position.x) + "," + to_text(s.position.y) + "," + to_text(s.position.z);
  return key;
}

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

std::string band_key(const std::vector<std::string>& bands, size_t b) {
  return bands[b].size() <= kBandKeyLength ? bands[b] : "b" + std::to_string(b + 1);
}

double pivot_wavelength_nm(const Passband& p) {
  const double up = passband_integral(p, [](double l) { return l; }, kPassbandSubdivisions);
  const double down = passband_integral(p, [](double l) { return 1.0 / l; }, kPassbandSubdivisions);
  return std::sqrt(up / down);
}

MetaEntries camera_wcs(const CameraSettings& c) {
  MetaEntries w;
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  // Pixel centres are integers in FITS, (1, 1) the lower left; the camera
  // axis passes between the middle pixels of an even image.
  const double crpix1 = 0.5 * (c.width + 1), crpix2 = 0.5 * (c.height + 1);
  std::string type1, type2, unit;
  double step = 0;
  if (c.projection == Projection::Orthographic) {
    type1 = "OFFSET_X";
    type2 = "OFFSET_Y";
    unit = "pc";
    step = c.ortho_width / c.width;  // square pixels
  } else if (c.projection == Projection::Perspective) {
    // A pinhole camera is the gnomonic (TAN) projection; square pixels.
    type1 = "OFLN-TAN";
    type2 = "OFLT-TAN";
    unit = "deg";
    step = kDeg * 2.0 * std::tan(0.5 * c.fov_deg / kDeg) / c.height;
  } else {
    // The dome master is azimuthal equidistant (ARC): 90 degrees at the rim.
    type1 = "OFLN-ARC";
    type2 = "OFLT-ARC";
    unit = "deg";
    step = 180.0 / c.height;
  }
  w.push_back({"WCSAXES", 3});
  w.push_back({"CTYPE1", type1});
  w.push_back({"CTYPE2", type2});
  w.push_back({"CTYPE3", "BAND"});
  w.push_back({"CUNIT1", unit});
  w.push_back({"CUNIT2", unit});
  w.push_back({"CRPIX1", crpix1});
  w.push_back({"CRPIX2", crpix2});
  w.push_back({"CRPIX3", 1.0});
  w.push_back({"CRVAL1", 0.0});
  w.push_back({"CRVAL2", 0.0});
  w.push_back({"CRVAL3", 1.0});
  w.push_back({"CDELT1", step});
  w.push_back({"CDELT2", step});
  w.push_back({"CDELT3", 1.0});
  if (c.projection != Projection::Orthographic) w.push_back({"LONPOLE", 180.0});
  return w;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return text;
}

ImageMetadata scene_metadata(const Scene& scene, const SceneBands& bands, const CameraSettings& camera,
                             const std::string& mode) {
  ImageMetadata meta;
  meta.units = kRadianceUnit;
  // The pixels are radiance; the exposure is a display setting, applied
  // only when the image is tone-mapped (PNG).
  meta.exposure = camera.exposure;
  meta.display = scene.display;  // PNG only
  meta.entries = camera_wcs(camera);
  meta.entries.push_back({"DATE", utc_now()});
  meta.entries.push_back({"software", std::string("nebula ") + NEBULA_VERSION});
  meta.entries.push_back({"git_commit", NEBULA_GIT_COMMIT});
  meta.entries.push_back({"scene", scene.path});
  meta.entries.push_back({"mode", mode});
  for (size_t b = 0; b < scene.bands.size(); ++b) {
    const std::string name = band_key(scene.bands, b);
    if (b < bands.filters.size() && !bands.filters[b].wavelength_nm.empty())
      meta.entries.push_back({"pivot_nm_" + name, pivot_wavelength_nm(bands.filters[b])});
    meta.entries.push_back({"albedo_" + name, scene.dust.albedo[b]});
    meta.entries.push_back({"g_" + name, scene.dust.g[b]});
    meta.entries.push_back({"ext_" + name, double(bands.bands[b].extinction_ratio)});
  }
  meta.entries.push_back({"R_V", scene.dust.R_V});
  meta.entries.push_back({"ext_law", to_string(scene.dust.law)});
  meta.entries.push_back({"cam_kind", to_string(camera.projection)});
  meta.entries.push_back({"cam_width", camera.width});
  meta.entries.push_back({"cam_height", camera.height});
  const char* axes[3] = {"x", "y", "z"};
  auto part = [](const Vec3& v, int i) { return double(i == 0 ? v.x : i == 1 ? v.y : v.z); };
  for (int i = 0; i < 3; ++i) meta.entries.push_back({std::string("cam_") + axes[i] + "_pc", part(camera.position, i)});
  for (int i = 0; i < 3; ++i)
    meta.entries.push_back({std::string("cam_look_") + axes[i] + "_pc", part(camera.look_at, i)});
  for (int i = 0; i < 3; ++i) meta.entries.push_back({std::string("cam_up_") + axes[i], part(camera.up, i)});
  if (camera.projection == Projection::Perspective) meta.entries.push_back({"cam_fov_deg", camera.fov_deg});
  if (camera.projection == Projection::Orthographic) meta.entries.push_back({"cam_ortho_pc", camera.ortho_width});
  meta.entries.push_back({"stars", static_cast<int>(scene.stars.size())});
  for (size_t k = 0; k < scene.stars.size(); ++k) {
    const SceneStar& star = scene.stars[k];
    const std::string s = "star" + std::to_string(k + 1) + "_";
    if (!star.name.empty()) meta.entries.push_back({s + "name", star.name});
    for (int i = 0; i < 3; ++i) meta.entries.push_back({s + axes[i] + "_pc", part(star.position, i)});
    if (!star.spectral_class.empty()) meta.entries.push_back({s + "class", star.spectral_class});
    meta.entries.push_back({s + "T_K", star.temperature_K});
    meta.entries.push_back({s + "L_Lsun", star.luminosity_lsun});
    if (k < bands.stars.size())
      for (size_t b = 0; b < scene.bands.size() && b < bands.stars[k].power.size(); ++b)
        meta.entries.push_back({s + "P_" + band_key(scene.bands, b), double(bands.stars[k].power[b])});
  }
  meta.scene_text = scene.resolved_toml;
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

void report_star_pixels(const Camera& camera, const std::vector<Vec3>& stars, RunReport& report) {
  const StarPixelCount n = count_star_pixels(camera, stars);
  report.star_pixels = n.pixels;
  report.star_pixel_cells = n.cells;
  report.star_pixel_rays = n.rays;
}

CameraSettings supersampled_camera(const CameraSettings& camera, int samples_per_pixel) {
  const int k = samples_per_pixel_side(samples_per_pixel);
  CameraSettings fine = camera;
  fine.width = camera.width * k;
  fine.height = camera.height * k;
  return fine;
}

Image box_downsample(Image fine, int k) {
  if (k == 1) return fine;
  Image out(fine.width / k, fine.height / k, fine.bands);
  const double weight = 1.0 / (double(k) * k);
  for (size_t b = 0; b < fine.bands.size(); ++b)
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x) {
        double sum = 0;
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i) sum += fine.at(int(b), x * k + i, y * k + j);
        out.at(int(b), x, y) = static_cast<float>(sum * weight);
      }
  return out;
}

// What the image's light between voxels came from, for its metadata.
std::string multiple_scattering_text(const RunReport& r) {
  if (r.diffuse.done)
    return std::string(r.diffuse.axial ? "axial " : "") + "diffuse order " + std::to_string(r.diffuse.order) +
           (r.diffuse.zonal > 0 ? " with zonal degrees to " + std::to_string(r.diffuse.zonal) : std::string()) + ", " +
           std::to_string(r.diffuse.cells.nx) + "x" +
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
  options.degree = resolved_order(scene.diffuse, scene.dust.g);
  options.zonal = resolved_zonal(scene.diffuse, scene.dust.g);
  options.cells = scene.diffuse.cells;
  options.photons = scene.diffuse.photons;
  options.seed = scene.diffuse.seed;
  options.taper = scene.diffuse.taper;
  return options;
}

DiffuseReport diffuse_report(const std::vector<DiffuseBand>& bands, const DiffuseBakeOptions& options,
                             const DiffuseField& field, int voxels_per_cell, const DiffuseBakeStats& stats,
                             double wall_seconds) {
  DiffuseReport r;
  r.done = true;
  r.order = options.degree;
  r.zonal = field.n_zonal() > 0 ? field.zonal : 0;
  r.zonal_stars = r.zonal > 0 ? field.zonal_stars : 0;
  r.lanczos = resolved_taper(options.taper, options.degree, options.zonal) == DiffuseTaper::Lanczos;
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
