#pragma once
// Internal to scene/: the [display] table of a scene file (docs/scene.md):
// how PNGs and the viewer show the radiance; never the science pixels.
#include <toml++/toml.h>

#include "core/display.h"
#include "scene/camera_path_toml.h"

namespace nebula::scene_detail {

DisplaySettings parse_display(const toml::node& display, const FailFunction& fail);

}  // namespace nebula::scene_detail
