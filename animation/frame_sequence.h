#pragma once
// Frame sequences of `nebula animate`: the printf-style file pattern
// (frames/frame_%04d.png), which frames a run covers and their times, and the
// video made from them. Errors are ParameterErrors naming the parameter as
// AnimateOptions spells it ("pattern", "fps", "duration", "from", "to",
// "video"); the command maps them to its options.
#include <optional>
#include <string>

#include "scene/camera_path.h"

namespace nebula {

// One %d conversion with an optional zero-padded width (%d, %4d, %04d);
// "%%" is a literal percent sign. What ffmpeg's image2 reader reads too.
struct FramePattern {
  std::string prefix, suffix;  // around the number, "%%" already made "%"
  int width = 0;               // minimum digits
  bool zero_pad = false;
  std::string text;            // as given
  std::string path(long long frame) const;
  std::string folder() const;  // the folder part, "." when none
};
// Throws ParameterError("pattern", ...) for no %d, two of them, another conversion, a width over 12.
FramePattern parse_frame_pattern(const std::string& text);

// Frame k shows time start + k / fps (from the path's first key); the run covers
// the frames whose times lie in [from, to] (the whole path by default, both ends included).
struct FramePlan {
  double fps = 30;
  double start = 0;           // the path's first key time
  long long first = 0, last = 0;  // inclusive
  long long count() const { return last - first + 1; }
  double time(long long k) const { return start + double(k) / fps; }
};

// `duration` retimes the path (key times scaled about the first key so the
// path lasts that long); `from` and `to` are times on the (retimed) path.
// ParameterErrors: "fps" (not in (0, 1000]), "duration" (not > 0), "from",
// "to" (outside the path, or to before from, or no frame time between them).
CameraPath retime_path(const CameraPath& path, std::optional<double> duration);
FramePlan plan_frames(const CameraPath& path, double fps, std::optional<double> from, std::optional<double> to);

// The ffmpeg found on PATH, or "" (looked up without running it).
std::string find_ffmpeg();

// Encodes frames plan.first..plan.last of a PNG pattern as H.264 MP4 into a
// temporary beside `video` and renames it into place. Throws Error naming
// "video" on failure (ffmpeg's exit status).
void encode_video(const std::string& ffmpeg, const FramePattern& pattern, const FramePlan& plan, const std::string& video,
                  bool quiet);

}  // namespace nebula
