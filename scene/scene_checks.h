#pragma once
// Internal to scene/: the range checks shared by validate_scene and
// load_scene. Each returns the first problem with its key named as in the
// scene file (docs/scene.md), or nothing.
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

// "B", "V" or "R": the bands with passbands and extinction ratios.
bool known_band(const std::string& band);

inline std::string number_text(double v) { return to_text(v); }

}  // namespace nebula::scene_detail
