#pragma once
// Camera paths for fly-throughs (`nebula animate`, the viewer's recording):
// keyframes of the camera (time, position, look-at point, up, field of view)
// and the camera at any time between them. Positions and look-at points
// follow centripetal Catmull-Rom splines (alpha = 1/2: no cusps or loops
// within a segment, Yuksel, Schaefer & Keyser 2011); the up vector the same
// spline, normalised; the field of view a monotone cubic (never beyond its
// neighbouring keys). docs/scene.md, "[animation]", documents the keys.
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/vec3.h"

namespace nebula {

struct CameraKeyframe {
  double time = 0;  // seconds
  Vec3 position, look_at, up{0, 0, 1};
  double fov_deg = 40;
};

// How frame times map onto the path: through each keyframe at its own time
// (the default), or at constant speed along the position spline from the
// first key's time to the last (keys in between are then passed when the
// distance travelled says so, not at their times).
enum class PathTiming { Keyframes, ConstantSpeed };
const char* to_string(PathTiming timing);  // "keyframes", "constant_speed"
bool parse_path_timing(const std::string& name, PathTiming& out);

struct CameraPath {
  std::vector<CameraKeyframe> keys;  // strictly increasing times
  PathTiming timing = PathTiming::Keyframes;
  double start() const { return keys.empty() ? 0 : keys.front().time; }
  double end() const { return keys.empty() ? 0 : keys.back().time; }
};

// The first problem of a path, its key named as in a scene file
// ("animation.keyframes", "animation.keyframes.2.time", ...): fewer than two
// keys, non-finite or non-increasing times, a key whose camera is not one
// (position at its look-at point, up along the view) given `base` for the rest.
struct CameraPathIssue {
  std::string key, reason;
};
std::optional<CameraPathIssue> camera_path_issue(const CameraPath& path, const CameraSettings& base);

// Evaluates a checked path. Times outside [start, end] are clamped. At a
// keyframe's time (within 1e-9 s relative) the key's own values are returned
// unchanged, so a frame there equals a render of that key's camera bit for
// bit (keyframe timing; with constant speed, the first and last keys).
class CameraPathSampler {
 public:
  // Throws Error("<key>: <reason>") for camera_path_issue.
  CameraPathSampler(CameraPath path, const CameraSettings& base);

  CameraSettings at(double time) const;  // `base` with the path's position, look-at, up and fov
  Vec3 position_at(double time) const;
  double length() const { return arc_.empty() ? 0 : arc_.back(); }  // of the position spline, parsecs
  const CameraPath& path() const { return path_; }

 private:
  struct Place {
    int segment = 0;
    double u = 0;  // 0..1 within the segment
    int key = -1;  // a keyframe hit exactly, or -1
  };
  Place place(double time) const;
  CameraSettings settings_at(const Place& p) const;

  CameraPath path_;
  CameraSettings base_;
  std::vector<double> fov_slopes_;  // the monotone cubic's tangent at each key (per unit u)
  // Constant speed: cumulative arc length at kSamples points per segment.
  std::vector<double> arc_;
};

// One centripetal Catmull-Rom segment from p1 (u = 0) to p2 (u = 1) with
// neighbours p0 and p3 (Barry-Goldman's pyramid). Coincident neighbours are
// replaced by reflections so every knot interval is positive; p1 == p2 gives p1.
Vec3 centripetal_catmull_rom(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, double u);

}  // namespace nebula
