#include "animation/frame_sequence.h"

#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"

extern char** environ;

namespace nebula {

namespace fs = std::filesystem;

std::string FramePattern::path(long long frame) const {
  std::string digits = std::to_string(frame < 0 ? -frame : frame);
  if (int(digits.size()) < width) digits.insert(0, size_t(width) - digits.size(), zero_pad ? '0' : ' ');
  return prefix + (frame < 0 ? "-" : "") + digits + suffix;
}

std::string FramePattern::folder() const {
  const fs::path parent = fs::path(prefix + "0" + suffix).parent_path();
  return parent.empty() ? "." : parent.string();
}

FramePattern parse_frame_pattern(const std::string& text) {
  FramePattern p;
  p.text = text;
  bool found = false;
  std::string* out = &p.prefix;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out->push_back(text[i]);
      continue;
    }
    if (i + 1 < text.size() && text[i + 1] == '%') {
      out->push_back('%');
      ++i;
      continue;
    }
    size_t j = i + 1;
    bool zero = false;
    if (j < text.size() && text[j] == '0') {
      zero = true;
      ++j;
    }
    const size_t digits_at = j;
    while (j < text.size() && text[j] >= '0' && text[j] <= '9') ++j;
    if (j >= text.size() || text[j] != 'd')
      throw ParameterError("pattern", "'" + text + "': only %d, %4d or %04d (the frame number) and %% may follow a %");
    if (found) throw ParameterError("pattern", "'" + text + "' has two frame numbers (%d); give one");
    const std::string width = text.substr(digits_at, j - digits_at);
    if (width.size() > 2 || (!width.empty() && std::stoi(width) > 12))
      throw ParameterError("pattern", "'" + text + "': a frame number of at most 12 digits");
    p.width = width.empty() ? 0 : std::stoi(width);
    p.zero_pad = zero;
    found = true;
    out = &p.suffix;
    i = j;
  }
  if (!found)
    throw ParameterError("pattern", "'" + text + "' has no frame number: write %04d where it goes (e.g. frames/frame_%04d.png)");
  if (p.suffix.find('/') != std::string::npos)
    throw ParameterError("pattern", "'" + text + "': the frame number must be in the file name, not a folder");
  return p;
}

CameraPath retime_path(const CameraPath& path, std::optional<double> duration) {
  if (!duration) return path;
  if (!(std::isfinite(*duration) && *duration > 0 && *duration <= 1e7))
    throw ParameterError("duration", "is " + to_text(*duration) + "; must be > 0 seconds");
  CameraPath out = path;
  const double t0 = path.start(), scale = *duration / (path.end() - path.start());
  for (size_t i = 1; i < out.keys.size(); ++i) out.keys[i].time = t0 + (path.keys[i].time - t0) * scale;
  out.keys.back().time = t0 + *duration;  // exactly, whatever the rounding above
  return out;
}

FramePlan plan_frames(const CameraPath& path, double fps, std::optional<double> from, std::optional<double> to) {
  if (!(std::isfinite(fps) && fps > 0 && fps <= 1000))
    throw ParameterError("fps", "is " + to_text(fps) + "; must be in (0, 1000] frames per second");
  FramePlan plan;
  plan.fps = fps;
  plan.start = path.start();
  const double a = from.value_or(path.start()), b = to.value_or(path.end());
  if (!(std::isfinite(a) && a >= path.start() && a <= path.end()))
    throw ParameterError("from", "is " + to_text(a) + " s; the path runs from " + to_text(path.start()) + " to " +
                                     to_text(path.end()) + " s");
  if (!(std::isfinite(b) && b >= path.start() && b <= path.end()))
    throw ParameterError("to", "is " + to_text(b) + " s; the path runs from " + to_text(path.start()) + " to " +
                                   to_text(path.end()) + " s");
  if (!(b >= a)) throw ParameterError("to", "is " + to_text(b) + " s, before from = " + to_text(a) + " s");
  // Frame times within a hair of a bound count as on it (k / fps rounds).
  const double eps = 1e-9;
  const double frames_in = (path.end() - path.start()) * fps;
  if (frames_in > 1e8) throw ParameterError("fps", "gives " + to_text(frames_in) + " frames; at most 1e8");
  plan.first = (long long)std::ceil((a - plan.start) * fps - eps);
  plan.last = (long long)std::floor((b - plan.start) * fps + eps);
  if (plan.last < plan.first)
    throw ParameterError("to", "no frame time lies between from = " + to_text(a) + " s and to = " + to_text(b) +
                                   " s at " + to_text(fps) + " frames per second");
  return plan;
}

std::string find_ffmpeg() {
  const char* env = std::getenv("PATH");
  std::string list = env ? env : "/usr/bin:/bin";
  size_t begin = 0;
  while (begin <= list.size()) {
    const size_t colon = list.find(':', begin);
    const std::string dir = list.substr(begin, colon == std::string::npos ? std::string::npos : colon - begin);
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) {
      struct stat st {};
      if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode)) return candidate;
    }
    if (colon == std::string::npos) break;
    begin = colon + 1;
  }
  return "";
}

void encode_video(const std::string& ffmpeg, const FramePattern& pattern, const FramePlan& plan, const std::string& video,
                  bool quiet) {
  TemporaryFile temporary(video);
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.17g", plan.fps);
  // ffmpeg's image2 reader takes the same %0Nd pattern; "%%" stays "%%" for it.
  std::vector<std::string> args = {ffmpeg,
                                   "-hide_banner",
                                   "-nostdin",
                                   "-loglevel",
                                   quiet ? "error" : "warning",
                                   "-y",
                                   "-framerate",
                                   rate,
                                   "-start_number",
                                   std::to_string(plan.first),
                                   "-i",
                                   pattern.text,
                                   "-frames:v",
                                   std::to_string(plan.count()),
                                   // H.264 in 4:2:0 needs even sizes: pad by one black row or column.
                                   "-vf",
                                   "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-c:v",
                                   "libx264",
                                   "-pix_fmt",
                                   "yuv420p",
                                   "-crf",
                                   "18",
                                   "-movflags",
                                   "+faststart",
                                   "-f",
                                   "mp4",
                                   temporary.path()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, ffmpeg.c_str(), nullptr, nullptr, argv.data(), environ) != 0)
    throw ParameterError("video", "cannot start " + ffmpeg);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw ParameterError("video", "ffmpeg failed (" +
                                      (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                                         : std::string("killed by a signal")) +
                                      ") encoding " + pattern.text + " to " + video);
  temporary.publish();
}

}  // namespace nebula
