#include "animation/animate.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/frame_pool.h"
#include "core/progress.h"
#include "imageio/image_output.h"

namespace nebula {
namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string exact(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string lower_extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// What a resumed run must match for its frames to be those of this run: the
// scene as resolved, the camera, the frame times and how pixels are made.
std::string manifest_text(const Scene& scene, const CameraPath& path, const AnimateOptions& o) {
  std::ostringstream m;
  m << "# nebula animate: the run whose frames lie here (a resumed run must match it)\n";
  m << "pattern = " << o.pattern << "\nfps = " << exact(o.fps) << "\nscene = " << scene.path << "\n";
  const CameraSettings& c = scene.camera;
  m << "camera = " << to_string(c.projection) << " " << c.width << "x" << c.height << " exposure " << exact(c.exposure)
    << " ortho_width " << exact(c.ortho_width) << "\n";
  m << "timing = " << to_string(path.timing) << "\n";
  for (const CameraKeyframe& k : path.keys)
    m << "key = " << exact(k.time) << " [" << exact(k.position.x) << " " << exact(k.position.y) << " "
      << exact(k.position.z) << "] [" << exact(k.look_at.x) << " " << exact(k.look_at.y) << " " << exact(k.look_at.z)
      << "] [" << exact(k.up.x) << " " << exact(k.up.y) << " " << exact(k.up.z) << "] " << exact(k.fov_deg) << "\n";
  m << "smooth_step = " << exact(o.render.smooth_step) << "\ntable_photons = " << o.render.table_photons << "\n";
  m << "scene_toml = <<\n" << scene.resolved_toml << "\n>>\n";
  return m.str();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text_atomically(const std::string& path, const std::string& text) {
  TemporaryFile temporary(path);
  {
    std::ofstream out(temporary.path(), std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) throw Error("cannot write " + path);
  }
  temporary.publish();
}

}  // namespace

std::string manifest_path(const FramePattern& pattern) {
  const fs::path prefix(pattern.prefix);
  const std::string stem = pattern.prefix.empty() || pattern.prefix.back() == '/' ? "" : prefix.filename().string();
  return (fs::path(pattern.folder()) / (stem + "animate.txt")).string();
}

AnimateResult animate(const Scene& scene, const AnimateOptions& o) {
  // ---- every check first: nothing is written on bad input.
  if (!scene.camera_path)
    throw Error(scene.path + ": animation: the scene has no camera path; add [[animation.keyframes]] entries (time, "
                             "position, look_at, ...; docs/scene.md)");
  const FramePattern pattern = parse_frame_pattern(o.pattern);
  try {
    check_image_format(pattern.path(0));
  } catch (const Error& e) {
    throw ParameterError("pattern", e.what());
  }
  const CameraPath path = retime_path(*scene.camera_path, o.duration);
  const FramePlan plan = plan_frames(path, o.fps, o.from, o.to);
  const CameraPathSampler sampler(path, scene.camera);
  for (long long k = plan.first; k <= plan.last; ++k)
    if (auto issue = camera_issue(sampler.at(plan.time(k))))
      throw Error(scene.path + ": animation.keyframes: the camera at frame " + std::to_string(k) + " (t = " +
                  to_text(plan.time(k)) + " s) has " + issue->field + " " + issue->reason);
  const std::string folder = pattern.folder();
  std::error_code ec;
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    throw ParameterError("pattern", "'" + folder + "' exists and is not a folder");
  if (fs::exists(folder, ec) && ::access(folder.c_str(), W_OK) != 0)
    throw ParameterError("pattern", "cannot write in the folder '" + folder + "' (" + std::strerror(errno) + ")");
  long long existing = 0;
  std::string first_existing;
  for (long long k = plan.first; k <= plan.last; ++k)
    if (fs::exists(pattern.path(k), ec)) {
      if (fs::is_directory(pattern.path(k), ec)) throw ParameterError("pattern", pattern.path(k) + " is a folder");
      if (existing++ == 0) first_existing = pattern.path(k);
    }
  const std::string manifest = manifest_path(pattern);
  const std::string record = manifest_text(scene, path, o);
  if (o.resume && o.force) throw ParameterError("resume", "and force exclude each other");
  if (existing > 0 && !o.force && !o.resume)
    throw ParameterError("pattern", "'" + folder + "' already holds " + std::to_string(existing) + " frame" +
                                        (existing == 1 ? "" : "s") + " of this pattern (" + first_existing + ")" +
                                        o.existing_hint);
  if (o.resume && existing > 0) {
    if (!fs::exists(manifest, ec))
      throw ParameterError("resume", "'" + folder + "' has frames but no record of their run (" + manifest +
                                         "): they cannot be checked against this one");
    if (read_text(manifest) != record)
      throw ParameterError("resume", "the frames in '" + folder + "' were made by another run (" + manifest +
                                         " differs: scene, camera path, frame rate or options)");
  }
  std::string ffmpeg;
  if (!o.video.empty()) {
    if (lower_extension(o.video) != ".mp4") throw ParameterError("video", "'" + o.video + "': must end in .mp4");
    if (lower_extension(pattern.path(0)) != ".png")
      throw ParameterError("video", "needs PNG frames (a pattern ending in .png), not " + lower_extension(pattern.path(0)));
    ffmpeg = find_ffmpeg();
    if (ffmpeg.empty())
      throw ParameterError("video", "ffmpeg is not installed (Debian: apt-get install ffmpeg); render the frames "
                                    "without it and encode them later, e.g. ffmpeg -framerate " + to_text(o.fps) +
                                    " -i '" + o.pattern + "' -c:v libx264 -pix_fmt yuv420p out.mp4");
    try {
      check_output_target(o.video, o.force, "folder", true);
    } catch (const Error& e) {
      throw ParameterError("video", e.what());
    }
  }
  if (!scene.axial) check_run_memory(scene, RunKind::Fast);

  // ---- the run.
  AnimateResult result;
  result.plan = plan;
  result.manifest = manifest;
  const bool made_folder = !fs::exists(folder, ec);
  fs::create_directories(folder, ec);
  if (ec) throw ParameterError("pattern", "cannot make the folder '" + folder + "' (" + ec.message() + ")");
  const bool had_manifest = fs::exists(manifest, ec);
  const std::string old_manifest = had_manifest ? read_text(manifest) : "";
  write_text_atomically(manifest, record);
  // A failure before the first frame (a bake refused, say) leaves the disk as it was.
  struct Undo {
    bool armed = true;
    std::function<void()> action;
    ~Undo() {
      if (armed) action();
    }
  } undo{true, [&] {
    std::error_code ignored;
    if (had_manifest)
      write_text_atomically(manifest, old_manifest);
    else
      fs::remove(manifest, ignored);
    if (made_folder) fs::remove(folder, ignored);  // only when empty
  }};

  // One bake for every frame. PreparedGrid points into itself (the diffuse
  // field, the bakes): it stays where prepare_grid built it, never moved.
  auto run_frames = [&](const std::function<RenderOutput(const CameraSettings&)>& render_frame) {
    std::unique_ptr<Progress> bar;
    long long to_render = 0;
    for (long long k = plan.first; k <= plan.last; ++k)
      to_render += (o.resume && fs::exists(pattern.path(k), ec)) ? 0 : 1;
    if (o.progress) bar = std::make_unique<Progress>("animate", uint64_t(std::max(to_render, 1LL)));
    for (long long k = plan.first; k <= plan.last; ++k) {
      const std::string file = pattern.path(k);
      if (o.resume && fs::exists(file, ec)) {
        ++result.skipped;
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      RenderOutput frame = render_frame(sampler.at(plan.time(k)));
      result.render_seconds += seconds_since(t0);
      if (result.rendered == 0) {
        if (!scene.axial) {
          frame.report.total_seconds = result.prepare_seconds + seconds_since(t0);
        }
        result.report = frame.report;
      }
      frame.metadata.entries.push_back({"frame", k});
      frame.metadata.entries.push_back({"frame_time_s", plan.time(k)});
      const auto t1 = std::chrono::steady_clock::now();
      write_image(frame.image, file, frame.metadata, true);
      recycle_frame_image(std::move(frame.image));  // the next frame's memory
      undo.armed = false;
      result.write_seconds += seconds_since(t1);
      ++result.rendered;
      if (bar) bar->add(1);
    }
    if (bar) bar->finish();
  };
  const auto t_prepare = std::chrono::steady_clock::now();
  if (!scene.axial) {
    PreparedGrid prepared = prepare_grid(scene, o.render);
    prepared.options.progress = false;  // one bar over the frames instead of one per frame
    result.report = prepared.report;
    result.prepare_seconds = seconds_since(t_prepare);
    run_frames([&](const CameraSettings& camera) { return render_prepared(prepared, camera); });
  } else {
    // An axial map bakes with its render (its bake is the map's, cheap beside a 3D grid's).
    RenderOptions quiet = o.render;
    quiet.progress = false;
    run_frames([&](const CameraSettings& camera) {
      Scene copy = scene;
      copy.camera = camera;
      return render_scene(copy, quiet);
    });
  }
  if (!ffmpeg.empty()) {
    encode_video(ffmpeg, pattern, plan, o.video, o.quiet);
    result.video = o.video;
  }
  return result;
}

}  // namespace nebula
