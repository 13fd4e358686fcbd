#pragma once
// Internal to scene/: the [animation] table of a scene file (docs/scene.md)
// read into a CameraPath. Kept apart from scene_file.cpp, which calls it.
#include <functional>
#include <string>

#include <toml++/toml.h>

#include "core/camera.h"
#include "scene/camera_path.h"

namespace nebula::scene_detail {

// `fail(key, reason)` throws (the scene parser's one-line Error naming the
// file, the key and any override that set it). Keys a keyframe leaves out
// (look_at, up, fov_deg) come from `camera`, the scene's [camera].
using FailFunction = std::function<void(const std::string& key, const std::string& reason)>;
CameraPath parse_camera_path(const toml::node& animation, const CameraSettings& camera, const FailFunction& fail);

}  // namespace nebula::scene_detail
