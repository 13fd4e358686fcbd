#pragma once
// Internal to scene/: the range checks shared by validate_scene and
// load_scene. Each returns the first problem with its key named as in the
// scene file (docs/scene.md), or nothing.
#include <cmath>
#include <optional>
#include <string>

#include "core/error.h"

#include "scene/scene.h"

namespace nebula::scene_detail {

struct SceneIssue {
  std::string key, reason;
};

// A spectral class and an explicit temperature agree within this (K): the
// class table lists whole kelvins.
constexpr double kClassTemperatureTolerance = 0.5;

// Bands, dust, stars, camera and output: everything but the grids.
std::optional<SceneIssue> settings_issue(const Scene& scene);

// The density and emission grids: shapes, sizes and values.
std::optional<SceneIssue> grids_issue(const Scene& scene);

// A band a scene may render (illumination/filters.h, or one of the scene's
// own [filters]), or its issue.
std::optional<SceneIssue> band_issue(const std::string& band, const std::vector<SceneFilter>& filters = {});
std::optional<SceneIssue> samples_per_pixel_issue(int n);

inline std::string number_text(double v) { return to_text(v); }

inline bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// "[x, y, z]" as messages print a position or direction.
inline std::string vec_text(Vec3 v) {
  return "[" + to_text(v.x) + ", " + to_text(v.y) + ", " + to_text(v.z) + "]";
}

}  // namespace nebula::scene_detail
