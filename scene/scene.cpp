#include "scene/scene.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/bands.h"
#include "core/error.h"
#include "illumination/extinction.h"
#include "illumination/filters.h"
#include "illumination/star.h"
#include "scene/density_sources.h"
#include "scene/scene_checks.h"

namespace nebula {

int resolved_zonal(const DiffuseSettings& d, const std::vector<double>& g) {
  if (d.zonal != DiffuseSettings::kZonalAuto) return d.zonal;
  // Strongly forward dust only: at g = 0.9 the harmonics alone misplace the
  // light near a star by 20-30% per pixel, at g = 0.6 the zonal degrees
  // change little (docs/diffuse.md, "Zonal degrees").
  for (double x : g)
    if (x >= 0.8) return std::max(24, d.order + 1);
  return 0;
}

int resolved_order(const DiffuseSettings& d, const std::vector<double>& g) {
  if (d.order != DiffuseSettings::kOrderAuto) return d.order;
  // Degree 4 takes back-scattering from a layer behind the star within 5%
  // of the truth at g = 0.6 (degree 3: +6%) and costs the 1080p frame about
  // 0.1 ms at 256^3; with zonal degrees it brought layer_behind at g = 0.9
  // from +4.9% to +5.9% and cost the frame 0.2 ms more, so 3 there
  // (docs/diffuse.md, "The degree").
  return resolved_zonal(d, g) > 0 ? 3 : 4;
}

const char* to_string(MultipleScattering mode) {
  switch (mode) {
    case MultipleScattering::Diffuse: return "diffuse";
    case MultipleScattering::Pyramid: return "pyramid";
    default: return "none";
  }
}

bool parse_multiple_scattering(const std::string& name, MultipleScattering& out) {
  for (MultipleScattering m : {MultipleScattering::Diffuse, MultipleScattering::Pyramid, MultipleScattering::None})
    if (name == to_string(m)) {
      out = m;
      return true;
    }
  return false;
}

CameraSettings scene_camera_defaults() {
  CameraSettings c;
  c.position = c.look_at = Vec3{0, 0, 0};
  c.up = Vec3{0, 0, 1};
  return c;
}

namespace scene_detail {
namespace {

bool all_equal(const std::vector<double>& v) {
  for (double x : v)
    if (!(x == v.front())) return false;
  return true;
}

// Checks one per-band dust quantity; the key is "dust.<name>" when every band
// has the same value (one number in the file) and "dust.<name>.<band>" otherwise.
template <class Good>
std::optional<SceneIssue> per_band_issue(const Scene& s, const std::vector<double>& values,
                                         const std::string& name, const std::string& range,
                                         Good good) {
  if (values.size() != s.bands.size())
    return SceneIssue{"dust." + name, "has " + std::to_string(values.size()) + " values for " +
                                          std::to_string(s.bands.size()) + " bands"};
  for (size_t b = 0; b < values.size(); ++b)
    if (!(std::isfinite(values[b]) && good(values[b])))
      return SceneIssue{all_equal(values) ? "dust." + name : "dust." + name + "." + s.bands[b],
                        "is " + to_text(values[b]) + "; must be " + range};
  return std::nullopt;
}

std::optional<SceneIssue> star_issue(const SceneStar& star, const std::string& key) {
  if (!finite(star.position)) return SceneIssue{key + ".position", "must be finite"};
  if (!(std::isfinite(star.luminosity_lsun) && star.luminosity_lsun > 0))
    return SceneIssue{key + ".luminosity_lsun",
                      "is " + to_text(star.luminosity_lsun) + "; must be > 0 (L_sun)"};
  if (star.luminosity_lsun > kMaxLuminosityLsun)
    return SceneIssue{key + ".luminosity_lsun", "is " + to_text(star.luminosity_lsun) + "; must be at most " +
                                                    to_text(kMaxLuminosityLsun) +
                                                    " L_sun (a galaxy's; radiance is computed in single precision)"};
  if (!(std::isfinite(star.temperature_K) && star.temperature_K > 0))
    return SceneIssue{key + ".temperature_K",
                      "is " + to_text(star.temperature_K) + "; must be > 0 (K)"};
  if (!star.spectral_class.empty()) {
    double t = 0;
    try {
      t = effective_temperature_K(star.spectral_class);
    } catch (const Error& e) {
      return SceneIssue{key + ".class", e.what()};
    }
    if (std::fabs(t - star.temperature_K) > kClassTemperatureTolerance)
      return SceneIssue{key + ".temperature_K",
                        "is " + to_text(star.temperature_K) + " K but class '" +
                            star.spectral_class + "' has " + to_text(t) +
                            " K (Pecaut & Mamajek 2013); give one of them, or both agreeing"};
  }
  return std::nullopt;
}

}  // namespace

std::optional<SceneIssue> band_issue(const std::string& band, const std::vector<SceneFilter>& filters) {
  if (is_renderable_filter(band) || band == kGreyBand) return std::nullopt;
  for (const SceneFilter& f : filters)
    if (f.name == band) return std::nullopt;
  std::string known;
  for (const std::string& name : renderable_filters()) known += (known.empty() ? "" : ", ") + name;
  return SceneIssue{"bands", "'" + band + "' is not a known band (known: " + known + ", " + kGreyBand +
                                 (filters.empty() ? "" : "; or a filter of the scene's [filters] table") + ")"};
}

std::optional<SceneIssue> filter_issue(const SceneFilter& f) {
  const std::string key = "filters." + f.name;
  const bool letter = !f.name.empty() && std::isalpha(static_cast<unsigned char>(f.name[0]));
  bool chars = f.name.size() <= 24;
  for (char c : f.name) chars = chars && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-');
  if (!letter || !chars)
    return SceneIssue{key, "a filter name is 1 to 24 characters of [A-Za-z0-9_-] starting with a letter"};
  if (f.name.size() >= 2 && f.name[0] == 'b' && f.name.find_first_not_of("0123456789", 1) == std::string::npos)
    return SceneIssue{key, "'" + f.name + "': b<number> names a plane in image metadata; give the filter another name"};
  if (is_renderable_filter(f.name))
    return SceneIssue{key, "'" + f.name + "' is a built-in filter (`nebula filters`); give the file another name"};
  const Passband& p = f.passband;
  if (p.wavelength_nm.size() < 2 || p.wavelength_nm.size() != p.response.size())
    return SceneIssue{key, "the curve '" + f.path + "' has fewer than 2 rows"};
  const double lo = 1000.0 / kExtinctionMaxInverseMicron, hi = 1000.0 / kExtinctionMinInverseMicron;
  if (!(p.wavelength_nm.front() >= lo && p.wavelength_nm.back() <= hi))
    return SceneIssue{key, "the curve '" + f.path + "' spans " + to_text(p.wavelength_nm.front()) + " to " +
                               to_text(p.wavelength_nm.back()) + " nm, outside the extinction law's " + to_text(lo) +
                               " to " + to_text(hi) + " nm"};
  return std::nullopt;
}

std::optional<SceneIssue> spectral_issue(const Scene& s) {
  const SpectralSpec& p = *s.spectral;
  const bool known_method = p.method == "double" || p.method == "analytic" || p.method == "projection" ||
                            p.method == "light_density" || p.method == "voxel_light" || p.method == "preintegrated";
  if (!known_method)
    return SceneIssue{"spectral.method", "'" + p.method +
                                             "' is not a method (known: double, analytic, projection, light_density, "
                                             "voxel_light, preintegrated)"};
  if (p.basis < 1 || p.basis > 16)
    return SceneIssue{"spectral.basis", "is " + std::to_string(p.basis) + "; must be in 1..16 (basis elements)"};
  if (p.wavelengths < 2 || p.wavelengths > 4096)
    return SceneIssue{"spectral.wavelengths", "is " + std::to_string(p.wavelengths) + "; must be in 2..4096"};
  if (p.attenuation != "law" && p.attenuation != "inverse")
    return SceneIssue{"spectral.attenuation", "'" + p.attenuation + "' is not an attenuation (known: law, inverse)"};
  if (p.method == "analytic" && p.attenuation != "inverse")
    return SceneIssue{"spectral.method", "analytic integrates polynomials times e^(-a/lambda): it needs "
                                         "spectral.attenuation = \"inverse\""};
  if (p.norm != "relative" && p.norm != "absolute")
    return SceneIssue{"spectral.norm", "'" + p.norm + "' is not a norm (known: relative, absolute)"};
  for (const auto& [key, v] : {std::pair{"spectral.fit_depth", p.fit_depth}, std::pair{"spectral.max_depth", p.max_depth}})
    if (!(std::isfinite(v) && v >= 0 && v <= 1000))
      return SceneIssue{key, "is " + to_text(v) + "; must be in [0, 1000] (V-band optical depth; 0: automatic)"};
  if (!(std::isfinite(p.near_voxels) && p.near_voxels >= 0 && p.near_voxels <= 1000))
    return SceneIssue{"spectral.near_voxels", "is " + to_text(p.near_voxels) + "; must be in [0, 1000] (voxels)"};
  if (p.table_nodes < 1 || p.table_nodes > 4)
    return SceneIssue{"spectral.table_nodes",
                      "is " + std::to_string(p.table_nodes) + "; must be in 1..4 (attenuations the table is read at)"};
  if (p.fit_depth > 0 && p.max_depth > 0 && p.fit_depth > p.max_depth)
    return SceneIssue{"spectral.fit_depth", "is " + to_text(p.fit_depth) + ", beyond spectral.max_depth " +
                                                to_text(p.max_depth)};
  if (p.range_lo_um != 0 || p.range_hi_um != 0)
    if (!(std::isfinite(p.range_lo_um) && std::isfinite(p.range_hi_um) && p.range_lo_um > 0 &&
          p.range_hi_um > p.range_lo_um))
      return SceneIssue{"spectral.range_um", "must be [lo, hi] in um with 0 < lo < hi"};
  if (s.axial) return SceneIssue{"spectral", "the spectral renderer draws 3D grids; this scene is an axial map"};
  for (const std::string& band : s.bands)
    if (band == kGreyBand)
      return SceneIssue{"bands", "the grey band has no wavelengths; the spectral renderer integrates over filters"};
  if (!s.emission.empty())
    return SceneIssue{"emission", "holds one grid per band; the spectral renderer takes emission as lines and "
                                  "continua ([[spectral.emission]], docs/scene.md)"};
  for (size_t i = 0; i < p.emission.size(); ++i) {
    const SpectralEmissionSpec& c = p.emission[i];
    const std::string key = "spectral.emission." + std::to_string(i);
    if (c.continuum.empty() && !(std::isfinite(c.line_nm) && c.line_nm > 0))
      return SceneIssue{key + ".line_nm", "is " + to_text(c.line_nm) + "; must be a wavelength > 0 (nm)"};
    for (double v : c.continuum)
      if (!std::isfinite(v)) return SceneIssue{key + ".continuum", "holds " + to_text(v) + "; must be finite"};
    if ((c.lo_nm != 0 || c.hi_nm != 0) && !(std::isfinite(c.lo_nm) && std::isfinite(c.hi_nm) && c.lo_nm > 0 &&
                                             c.hi_nm > c.lo_nm))
      return SceneIssue{key + ".range_nm", "must be [lo, hi] in nm with 0 < lo < hi"};
    if (!(std::isfinite(c.scale) && c.scale >= 0))
      return SceneIssue{key + ".scale", "is " + to_text(c.scale) + "; must be >= 0 and finite"};
  }
  if (!all_equal(s.dust.albedo))
    return SceneIssue{"dust.albedo", "the spectral renderer takes one albedo, or a curve over wavelength in "
                                     "[spectral.dust]; give one number"};
  if (!all_equal(s.dust.g))
    return SceneIssue{"dust.g", "the spectral renderer takes one g, or a curve over wavelength in [spectral.dust]; "
                                "give one number"};
  for (size_t i = 0; i < p.dust_nm.size(); ++i)
    if (!(std::isfinite(p.dust_nm[i]) && p.dust_nm[i] > 0 && (i == 0 || p.dust_nm[i] > p.dust_nm[i - 1])))
      return SceneIssue{"spectral.dust.wavelength_nm", "must be positive wavelengths in nm, increasing"};
  for (double a : p.dust_albedo)
    if (!(a >= 0 && a <= 1)) return SceneIssue{"spectral.dust.albedo", "holds " + to_text(a) + "; must be in [0, 1]"};
  for (double g : p.dust_g)
    if (!(g > -1 && g < 1)) return SceneIssue{"spectral.dust.g", "holds " + to_text(g) + "; must be in (-1, 1)"};
  if (!p.dust_nm.empty()) {
    for (const std::string& f : s.dust.table_files)
      if (!f.empty())
        return SceneIssue{"dust.tables", "with [spectral.dust] every table node has its own albedo and g, so its "
                                         "own table (generated and cached); name none"};
    if (p.method == "double" && p.tables)
      return SceneIssue{"spectral.method", "the double integral would need a table per wavelength for [spectral.dust]; "
                                           "it takes the curves with spectral.tables = false (the thin-voxel limit)"};
  }
  for (const std::string& f : s.dust.table_files) {
    if (!f.empty() && !p.tables)
      return SceneIssue{"dust.tables", "spectral.tables = false (the thin-voxel limit) reads no scattering table"};
    if (f != s.dust.table_files.front())
      return SceneIssue{"dust.tables", "the spectral renderer reads one table at every wavelength; name the same "
                                       "file for every band"};
  }
  if (p.method == "projection" && s.stars.size() * size_t(p.basis) > 64)
    return SceneIssue{"spectral.basis", std::to_string(s.stars.size()) + " stars x " + std::to_string(p.basis) +
                                            " elements exceed the 64 numbers a ray carries; use method = "
                                            "\"voxel_light\" (up to 32 stars)"};
  if (p.method == "voxel_light" && s.stars.size() > 32)
    return SceneIssue{"stars", std::to_string(s.stars.size()) +
                                   " stars; the voxel-light method takes at most 32 (use method = \"light_density\")"};
  // The light-density basis is tabulated over star temperature (spectral/spectral_model.cpp).
  if (p.method == "light_density")
    for (size_t i = 0; i < s.stars.size(); ++i)
      if (!(s.stars[i].temperature_K >= 2000 && s.stars[i].temperature_K <= 60000))
        return SceneIssue{"stars." + std::to_string(i) + ".temperature_K",
                          "is " + to_text(s.stars[i].temperature_K) +
                              " K, outside the light-density basis' 2000 to 60000 K"};
  return std::nullopt;
}

std::optional<SceneIssue> samples_per_pixel_issue(int n) {
  const int side = samples_per_pixel_side(n);
  if (n < 1 || n > kMaxSamplesPerPixel || side * side != n)
    return SceneIssue{"render.samples_per_pixel", "is " + std::to_string(n) +
                                                      "; must be a square in 1..256 (1, 4, 9, 16, ...: k x k "
                                                      "stratified rays per pixel)"};
  return std::nullopt;
}

std::optional<SceneIssue> settings_issue(const Scene& s) {
  if (s.bands.empty()) return SceneIssue{"bands", "must name at least one band"};
  std::set<std::string> seen;
  std::set<std::string> filter_names;
  for (const SceneFilter& f : s.filters) {
    if (auto issue = filter_issue(f)) return issue;
    if (!filter_names.insert(f.name).second) return SceneIssue{"filters." + f.name, "appears twice"};
  }
  for (const std::string& band : s.bands) {
    if (auto issue = band_issue(band, s.filters)) return issue;
    if (!seen.insert(band).second) return SceneIssue{"bands", "'" + band + "' appears twice"};
  }
  if (auto issue = per_band_issue(s, s.dust.albedo, "albedo", "in [0, 1]",
                                  [](double a) { return a >= 0 && a <= 1; }))
    return issue;
  if (auto issue = per_band_issue(s, s.dust.g, "g", "in (-1, 1)",
                                  [](double g) { return std::fabs(g) < 1; }))
    return issue;
  if (!(std::isfinite(s.dust.R_V) && s.dust.R_V >= kMinRV && s.dust.R_V <= kMaxRV))
    return SceneIssue{"dust.R_V", "is " + to_text(s.dust.R_V) + "; must be in [" +
                                      to_text(kMinRV) + ", " + to_text(kMaxRV) +
                                      "], where the extinction law holds"};
  if (!s.dust.table_files.empty() && s.dust.table_files.size() != s.bands.size())
    return SceneIssue{"dust.tables", "has " + std::to_string(s.dust.table_files.size()) +
                                         " entries for " + std::to_string(s.bands.size()) +
                                         " bands"};
  for (size_t i = 0; i < s.stars.size(); ++i)
    if (auto issue = star_issue(s.stars[i], "stars." + std::to_string(i))) return issue;
  if (auto issue = camera_issue(s.camera)) return SceneIssue{"camera." + issue->field, issue->reason};
  if (s.output.empty()) return SceneIssue{"output.file", "must not be empty"};
  if (!(std::isfinite(s.star_psf_pixels) && s.star_psf_pixels > 0 && s.star_psf_pixels <= 1000))
    return SceneIssue{"output.star_psf_pixels",
                      "is " + to_text(s.star_psf_pixels) + "; must be in (0, 1000]"};
  if (s.pyramid_levels < 0 || s.pyramid_levels > 16)
    return SceneIssue{"render.levels", "is " + std::to_string(s.pyramid_levels) + "; must be in 0..16"};
  if (s.pyramid_levels > 0 && s.multiple_scattering != MultipleScattering::Pyramid)
    return SceneIssue{"render.levels", "is " + std::to_string(s.pyramid_levels) +
                                           " but render.multiple_scattering is \"" + to_string(s.multiple_scattering) +
                                           "\": levels belong to the pyramid (set multiple_scattering = \"pyramid\")"};
  if (s.diffuse.order != DiffuseSettings::kOrderAuto && (s.diffuse.order < 0 || s.diffuse.order > 4))
    return SceneIssue{"render.diffuse_order", "is " + std::to_string(s.diffuse.order) + "; must be \"auto\" or in 0..4"};
  if (s.diffuse.zonal != 0 && s.diffuse.zonal != DiffuseSettings::kZonalAuto &&
      (s.diffuse.zonal <= resolved_order(s.diffuse, s.dust.g) || s.diffuse.zonal > 32))
    return SceneIssue{"render.diffuse_zonal", "is " + std::to_string(s.diffuse.zonal) +
                                                  "; must be \"auto\", 0 (none) or above render.diffuse_order, at most 32"};
  if (s.diffuse.cells < 1 || s.diffuse.cells > 4096)
    return SceneIssue{"render.diffuse_cells", "is " + std::to_string(s.diffuse.cells) + "; must be in 1..4096"};
  if (s.diffuse.photons < 1 || s.diffuse.photons > 0xFFFFFFFFull)
    return SceneIssue{"render.diffuse_photons",
                      "is " + std::to_string(s.diffuse.photons) + "; must be in 1..4294967295 (per band)"};
  if (auto issue = samples_per_pixel_issue(s.samples_per_pixel)) return issue;
  if (s.spectral) return spectral_issue(s);
  return std::nullopt;
}

std::optional<SceneIssue> grids_issue(const Scene& s) {
  if (s.axial) return std::nullopt;  // the map is built and checked by the axial renderer
  const GridShape& g = s.density.shape;
  if (g.nx < 1 || g.ny < 1 || g.nz < 1)
    return SceneIssue{"density", "the grid has a zero size (" + std::to_string(g.nx) + " x " +
                                     std::to_string(g.ny) + " x " + std::to_string(g.nz) + ")"};
  if (!(std::isfinite(g.voxel) && g.voxel > 0))
    return SceneIssue{"density", "voxel size " + to_text(g.voxel) + " must be > 0"};
  if (!finite(g.origin)) return SceneIssue{"density", "the grid origin must be finite"};
  try {
    check_grid_values("tau_v", g, s.density.tau_v);
  } catch (const Error& e) {
    return SceneIssue{"density", e.what()};
  }
  if (!s.emission.empty()) {
    if (s.emission.size() != s.bands.size())
      return SceneIssue{"emission", "has " + std::to_string(s.emission.size()) + " grids for " +
                                        std::to_string(s.bands.size()) + " bands"};
    for (size_t b = 0; b < s.emission.size(); ++b) {
      try {
        check_grid_values("emission " + s.bands[b], g, s.emission[b], "emission");
      } catch (const Error& e) {
        return SceneIssue{"emission", e.what()};
      }
    }
  }
  if (s.stars.empty() && s.emission.empty() && !(s.spectral && !s.spectral->emission.empty()))
    return SceneIssue{"stars", "the scene has no stars and no emission: nothing would shine"};
  return std::nullopt;
}

}  // namespace scene_detail

void validate_scene(const Scene& scene) {
  const std::string name = scene.path.empty() ? "scene" : scene.path;
  if (auto issue = scene_detail::settings_issue(scene))
    throw Error(name + ": " + issue->key + ": " + issue->reason);
  if (auto issue = scene_detail::grids_issue(scene))
    throw Error(name + ": " + issue->key + ": " + issue->reason);
}

}  // namespace nebula
