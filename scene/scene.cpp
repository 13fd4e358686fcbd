#include "scene/scene.h"

#include <cmath>
#include <cstdio>
#include <set>

#include "core/bands.h"
#include "core/error.h"
#include "illumination/filters.h"
#include "illumination/star.h"
#include "scene/density_sources.h"
#include "scene/scene_checks.h"

namespace nebula {

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

std::optional<SceneIssue> band_issue(const std::string& band) {
  if (is_renderable_filter(band) || band == kGreyBand) return std::nullopt;
  std::string known;
  for (const std::string& name : renderable_filters()) known += (known.empty() ? "" : ", ") + name;
  return SceneIssue{"bands", "'" + band + "' is not a known band (known: " + known + ", " + kGreyBand + ")"};
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
  for (const std::string& band : s.bands) {
    if (auto issue = band_issue(band)) return issue;
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
  if (s.diffuse.order < 0 || s.diffuse.order > 4)
    return SceneIssue{"render.diffuse_order", "is " + std::to_string(s.diffuse.order) + "; must be in 0..4"};
  if (s.diffuse.cells < 1 || s.diffuse.cells > 4096)
    return SceneIssue{"render.diffuse_cells", "is " + std::to_string(s.diffuse.cells) + "; must be in 1..4096"};
  if (s.diffuse.photons < 1 || s.diffuse.photons > 0xFFFFFFFFull)
    return SceneIssue{"render.diffuse_photons",
                      "is " + std::to_string(s.diffuse.photons) + "; must be in 1..4294967295 (per band)"};
  if (auto issue = samples_per_pixel_issue(s.samples_per_pixel)) return issue;
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
  if (s.stars.empty() && s.emission.empty())
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
