#include "viewer/viewer_session.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "pipeline/axial_map_source.h"
#include "pipeline/spectral_scene.h"
#include "reconstruct/reconstruct.h"
#include "scene/scene_file.h"
#include "viewer/demo_scene_text.h"

namespace nebula::viewer {
namespace {

// Passes of the ground truth accumulated for one view at most (256 samples per pixel).
constexpr int kTruthPasses = 128;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

// ------------------------------------------------------------ SceneSource

SceneSource SceneSource::from_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw Error(path + ": cannot read the scene file (" + std::strerror(err ? err : ENOENT) + ")");
  }
  std::ostringstream text;
  text << in.rdbuf();
  std::string dir = path.find('/') == std::string::npos ? "." : path.substr(0, path.find_last_of('/'));
  if (dir.empty()) dir = "/";
  return SceneSource(text.str(), path, dir);
}

SceneSource SceneSource::demo() { return SceneSource(kDemoSceneText, "demo", "."); }

void SceneSource::set(const std::string& key, const std::string& value) {
  unset(key);
  overrides_.emplace_back(key, value);
}

void SceneSource::unset(const std::string& key) {
  for (auto it = overrides_.begin(); it != overrides_.end();)
    it = it->first == key ? overrides_.erase(it) : it + 1;
}

std::vector<std::string> SceneSource::overrides() const {
  std::vector<std::string> out;
  for (const auto& [key, value] : overrides_) out.push_back(key + "=" + value);
  return out;
}

Scene SceneSource::load() const { return load_scene_text(text_, name_, base_dir_, overrides()); }

Scene SceneSource::load_reusing(const Scene& previous) const {
  return load_scene_text(text_, name_, base_dir_, overrides(), &previous);
}

std::string toml_number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  std::string s = text;
  // TOML floats need a dot or an exponent; integers are fine as they are.
  return s;
}

std::string toml_strings(const std::vector<std::string>& values) {
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i].find_first_of("\"\\\n") != std::string::npos)
      throw Error("'" + values[i] + "': a name with a quote, backslash or line break cannot be a scene value");
    out += (i ? ", \"" : "\"") + values[i] + "\"";
  }
  return out + "]";
}

std::string toml_vec3(Vec3 v) {
  char text[120];
  std::snprintf(text, sizeof text, "[%.9g, %.9g, %.9g]", double(v.x), double(v.y), double(v.z));
  return text;
}

void set_view_overrides(SceneSource& s, const CameraSettings& c, const DisplaySettings& d,
                        const std::vector<CameraKeyframe>& keys) {
  s.set("camera.kind", std::string("\"") + to_string(c.projection) + "\"");
  s.set("camera.position", toml_vec3(c.position));
  s.set("camera.look_at", toml_vec3(c.look_at));
  s.set("camera.up", toml_vec3(c.up));
  s.set("camera.fov_deg", toml_number(c.fov_deg));
  if (c.projection == Projection::Orthographic) s.set("camera.ortho_width", toml_number(c.ortho_width));
  s.set("camera.width", std::to_string(c.width));
  s.set("camera.height", std::to_string(c.height));
  s.set("camera.exposure", toml_number(c.exposure));
  s.set("display.stretch", std::string("\"") + to_string(d.stretch) + "\"");
  s.set("display.auto_exposure", d.auto_exposure ? "true" : "false");
  s.set("display.percentile", toml_number(d.percentile));
  s.set("display.white", toml_number(d.white));
  s.set("display.softening", toml_number(d.softening));
  if (keys.size() >= 2) {
    std::string array;
    for (const CameraKeyframe& k : keys)
      array += std::string(array.empty() ? "" : ", ") + "{time = " + toml_number(k.time) + ", position = " +
               toml_vec3(k.position) + ", look_at = " + toml_vec3(k.look_at) + ", up = " + toml_vec3(k.up) +
               ", fov_deg = " + toml_number(k.fov_deg) + "}";
    s.set("animation", "{keyframes = [" + array + "]}");
  }
}

BrushPlane brush_plane(const Scene& scene, const std::string& name, const std::string& option) {
  BrushPlane plane;
  if (name == "tau_v") return plane;
  std::string list;
  for (size_t b = 0; b < scene.bands.size(); ++b) {
    if (scene.bands[b] == name) {
      plane.band = int(b);
      return plane;
    }
    list += (list.empty() ? "" : ", ") + scene.bands[b];
  }
  throw Error(option + ": plane '" + name + "' is not tau_v or one of the scene's bands (" + list + ")");
}

// ------------------------------------------------------------ Session

struct Session::Baked {
  std::shared_ptr<const Scene> scene;
  RenderOptions options;
  PreparedGrid prepared;  // built in place: it points into itself and into *scene
  // After an edit, what the edit left unchanged (the star bakes after an albedo
  // edit, say) is taken from the previous bake, which stays whole for frames
  // still rendering from it.
  Baked(std::shared_ptr<const Scene> s, const RenderOptions& o, const Baked* previous, int coarsening)
      : scene(std::move(s)),
        options(o),
        prepared(per_frame()                              ? PreparedGrid{}
                 : previous && !previous->per_frame() ? prepare_grid(*scene, o, previous->prepared)
                                                          : prepare_grid(*scene, o)),
        spectral(scene->spectral ? prepare_spectral(*scene, o, previous ? previous->spectral.get() : nullptr)
                                 : nullptr) {
    // The previews' coarser grid (ViewerOptions::preview_coarsening), its bakes reused alike.
    const bool pyramid = scene->pyramid_levels > 0 || scene->multiple_scattering == MultipleScattering::Pyramid;
    if (per_frame() || pyramid || coarsening <= 0) return;
    const Baked* before = previous ? previous->coarse.get() : nullptr;
    coarse = std::make_unique<const Baked>(std::make_shared<const Scene>(coarsened_scene(*scene, coarsening)), o,
                                           before, 0);
  }
  // A [spectral] scene's model, tables, depth bakes and fields: each view is
  // then its per-view pass, march and resolve (pipeline/spectral_scene.h).
  std::shared_ptr<const PreparedSpectral> spectral;
  std::unique_ptr<const Baked> coarse;  // the previews' grid, or null

  // No grid of the band renderer: an axial map bakes with its render (cheap
  // beside a 3D grid's bake), a spectral scene keeps its own (`spectral`).
  bool per_frame() const { return scene->axial.has_value() || scene->spectral.has_value(); }

  RenderOutput render(const CameraSettings& camera, bool preview) const {
    if (preview && coarse) return coarse->render(camera, true);
    if (!per_frame()) return render_prepared(prepared, camera, preview);
    if (spectral) return render_prepared_spectral(*spectral, camera);
    Scene copy = *scene;
    copy.camera = camera;
    return render_scene(copy, options);
  }
};

Session::Session(SceneSource source, const ViewerOptions& options)
    : options_(options), source_(std::move(source)) {
  shown_scene_ = std::make_shared<const Scene>(source_.load());
  latest_scene_ = shown_scene_;
  status_.activity = "baking (" + why_ + ")";
  status_.busy = true;
  thread_ = std::thread([this] { work(); });
}

Session::~Session() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Session::edit(const std::string& key, const std::string& value) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    source_.set(key, value);
    ++wanted_version_;
    why_ = key + " changed";
  }
  wake_.notify_all();
}

void Session::set_filters(const std::vector<std::string>& bands) {
  std::vector<std::pair<std::string, Passband>> filters;
  for (const std::string& name : bands) filters.emplace_back(name, band_filter(*shown_scene_, name));
  const auto [lo, hi] = filters_span_um(filters);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> now = source_.overrides();
    const bool ours = !kept_range_.empty() &&
                      std::find(now.begin(), now.end(), "spectral.range_um=" + kept_range_) != now.end();
    const SpectralSpec* spec = shown_scene_->spectral ? &*shown_scene_->spectral : nullptr;
    const bool scene_pins = spec && (spec->range_lo_um > 0 || spec->range_hi_um > 0) && !ours;
    const PreparedSpectral* prepared = baked_ && baked_->spectral ? baked_->spectral.get() : nullptr;
    source_.set("bands", toml_strings(bands));
    why_ = "filters changed";
    if (!scene_pins && prepared) {
      const double range_lo = prepared->model.lo_um, range_hi = prepared->model.hi_um;
      char range[96];
      std::snprintf(range, sizeof range, "%.3g-%.3g um", range_lo, range_hi);
      if (lo >= range_lo && hi <= range_hi) {
        kept_range_ = "[" + toml_number(range_lo) + ", " + toml_number(range_hi) + "]";
        source_.set("spectral.range_um", kept_range_);
        why_ += std::string(" (on the basis of ") + range + ": tables and bakes kept)";
      } else {
        if (ours) source_.unset("spectral.range_um");
        kept_range_.clear();
        why_ += std::string(" (outside the basis' ") + range + ": model and bakes made again)";
      }
    }
    ++wanted_version_;
  }
  wake_.notify_all();
}

void Session::request(const CameraSettings& camera, bool preview) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    wanted_camera_ = camera;
    wanted_preview_ = preview;
    ++wanted_request_;
  }
  wake_.notify_all();
}

std::optional<Frame> Session::take_frame() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<Frame> out = std::move(frame_);
  frame_.reset();
  return out;
}

void Session::set_truth(bool on) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    truth_on_ = on;
    if (!on) truth_.reset();
  }
  wake_.notify_all();
}

std::optional<TruthFrame> Session::truth() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return truth_;
}

SessionStatus Session::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

bool Session::idle() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !working_ && wanted_version_ == baked_version_ &&
         (!wanted_camera_ || !baked_ || wanted_request_ == rendered_request_);
}

void Session::wait_idle() const {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] {
    return !working_ && wanted_version_ == baked_version_ &&
           (!wanted_camera_ || !baked_ || wanted_request_ == rendered_request_);
  });
}

SceneSource Session::source() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return source_;
}

std::shared_ptr<const PreparedGrid> Session::prepared() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!baked_ || baked_->per_frame() || baked_->scene->pyramid_levels > 0 ||
      baked_->scene->multiple_scattering == MultipleScattering::Pyramid)
    return nullptr;
  return std::shared_ptr<const PreparedGrid>(baked_, &baked_->prepared);
}

void Session::sync_scene() {
  std::lock_guard<std::mutex> lock(mutex_);
  shown_scene_ = latest_scene_;
}

std::string Session::saved_scene_text(const CameraSettings& camera, const DisplaySettings& display,
                                      const std::vector<CameraKeyframe>& keys) const {
  if (map_edited())
    throw Error("the map was painted or loaded: the scene is saved with its map file (viewer::save_scene)");
  SceneSource s = source();
  set_view_overrides(s, camera, display, keys);
  std::shared_ptr<const Scene> shown;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shown = latest_scene_;
  }
  const Scene scene = s.load_reusing(*shown);
  return "# Saved by nebula-view from " + s.name() + " and its edits; `nebula render` reproduces the view.\n" +
         scene.resolved_toml + "\n";
}

// ------------------------------------------------------------ the axial map

std::shared_ptr<const AxialMap> Session::axial_map() {
  std::shared_ptr<const Scene> scene;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (painted_) return painted_;
    scene = shown_scene_;
  }
  if (!scene->axial) throw Error("the scene has no [axial] map");
  if (!built_ || built_for_ != scene) {
    built_ = std::make_shared<const AxialMap>(build_axial_map(*scene));
    built_for_ = scene;
  }
  return built_;
}

PaintResult Session::paint(Stroke stroke) {
  const std::shared_ptr<const AxialMap> current = axial_map();
  stroke.brush.n_bands = int(scene().bands.size());
  AxialMap next = *current;  // the worker may be rendering the current one
  const PaintResult result = paint_axial_map(next, stroke.brush, stroke.dabs);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    painted_ = std::make_shared<const AxialMap>(std::move(next));
    ++wanted_version_;
    why_ = "the map was painted";
  }
  wake_.notify_all();
  return result;
}

void Session::load_map(const std::string& path) {
  std::shared_ptr<const Scene> scene;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scene = shown_scene_;
  }
  if (!scene->axial) throw Error(path + ": the scene has no [axial] map to replace");
  AxialMap m;
  m.tau_v = load_axial_plane_hdf5(path, "tau_v", m.nx, m.nr);
  for (size_t b = 0; b < scene->bands.size(); ++b) {
    const std::string name = kMapEmissionPrefix + scene->bands[b];
    int nx = 0, nr = 0;
    std::vector<float> plane;
    try {
      plane = load_axial_plane_hdf5(path, name, nx, nr, "emission");
    } catch (const Error& e) {
      // A file without emission datasets is a map of dust alone; one with some is checked whole.
      const std::string what = e.what();
      const size_t holds = what.find("(the file holds:");
      if (b == 0 && holds != std::string::npos && what.find(kMapEmissionPrefix, holds) == std::string::npos) break;
      throw;
    }
    if (nx != m.nx || nr != m.nr)
      throw Error(path + ": dataset '" + name + "' is " + std::to_string(nr) + " x " + std::to_string(nx) +
                  ", tau_v " + std::to_string(m.nr) + " x " + std::to_string(m.nx));
    m.emission.push_back(std::move(plane));
  }
  AxialMap placed;
  try {
    placed = place_axial_map(*scene, std::move(m));
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    painted_ = std::make_shared<const AxialMap>(std::move(placed));
    ++wanted_version_;
    why_ = "the map was loaded from " + path;
  }
  wake_.notify_all();
}

void Session::save_map(const std::string& path, bool overwrite) {
  const std::shared_ptr<const AxialMap> map = axial_map();
  write_axial_map_hdf5(*map, scene().bands, path, overwrite, kMapEmissionPrefix);
}

bool Session::map_edited() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return painted_ != nullptr;
}

void Session::revert_map() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!painted_) return;
    painted_.reset();
    ++wanted_version_;
    why_ = "the map was reverted to the scene's";
  }
  wake_.notify_all();
}

std::vector<std::string> save_scene(Session& session, const CameraSettings& camera, const DisplaySettings& display,
                                    const std::vector<CameraKeyframe>& keys, const std::string& path, bool force) {
  namespace fs = std::filesystem;
  check_output_target(path, force, "folder", true);
  const bool painted = session.map_edited();
  const fs::path map_path = fs::path(path).parent_path() / (fs::path(path).stem().string() + ".map.h5");
  if (painted) check_output_target(map_path.string(), force, "folder", true);
  SceneSource source = session.source();
  set_view_overrides(source, camera, display, keys);
  const Scene scene = source.load_reusing(session.scene());
  // Data files named relative to the scene's folder must stay findable (a
  // painted map is written beside the saved scene instead of the scene's own).
  const fs::path there = fs::absolute(fs::path(path)).parent_path().lexically_normal();
  const fs::path here = fs::absolute(fs::path(source.base_dir())).lexically_normal();
  for (const SceneInput& input : scene.inputs)
    if (input.key != "scene" && there != here && !(painted && input.key.rfind("axial.", 0) == 0))
      throw Error(path + ": save the scene in " + here.string() + ", the folder of " + source.name() + ": its " +
                  input.key + " is named relative to it");
  std::vector<std::string> written;
  std::string text;
  if (!painted) {
    text = session.saved_scene_text(camera, display, keys);
  } else {
    const std::shared_ptr<const AxialMap> map = session.axial_map();
    session.save_map(map_path.string(), force);
    written.push_back(map_path.string());
    const std::string body = scene_text_with_axial_file(scene.resolved_toml, map_path.filename().string(),
                                                        map->emission.empty() ? "" : kMapEmissionPrefix);
    try {
      load_scene_text(body, path, there.string());  // as `nebula render` will read it
    } catch (const Error& e) {
      throw Error(path + ": the scene with its painted map does not load (a bug: please report it): " + e.what());
    }
    text = "# Saved by nebula-view from " + source.name() + ", its edits and its painted map " +
           map_path.filename().string() + "; `nebula render` reproduces the view.\n" + body + "\n";
  }
  TemporaryFile temporary(path);
  {
    std::ofstream out(temporary.path(), std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) throw Error("cannot write " + path);
  }
  temporary.publish();
  written.push_back(path);
  return written;
}

void Session::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  SceneSource good = source_;  // the overrides of the last scene that loaded and baked
  while (true) {
    wake_.wait(lock, [&] {
      return stop_ || wanted_version_ != baked_version_ ||
             (wanted_camera_ && baked_ && wanted_request_ != rendered_request_) ||
             (truth_on_ && baked_ && truth_camera_ && (!truth_ || truth_->passes < kTruthPasses));
    });
    if (stop_) return;
    working_ = true;
    const bool other_work = wanted_version_ != baked_version_ || (wanted_camera_ && baked_ && wanted_request_ != rendered_request_);
    if (!other_work) {
      // A pass of the ground truth for the last view: only when nothing else waits.
      const CameraSettings camera = *truth_camera_;
      const std::shared_ptr<const Baked> current = baked_;
      const uint64_t version = baked_version_;
      std::optional<TruthFrame> sum = truth_;
      if (sum && (sum->version != version || !(sum->camera.width == camera.width && sum->camera.height == camera.height &&
                                               sum->camera.position.x == camera.position.x &&
                                               sum->camera.position.y == camera.position.y &&
                                               sum->camera.position.z == camera.position.z &&
                                               sum->camera.look_at.x == camera.look_at.x &&
                                               sum->camera.look_at.y == camera.look_at.y &&
                                               sum->camera.look_at.z == camera.look_at.z &&
                                               sum->camera.fov_deg == camera.fov_deg &&
                                               sum->camera.projection == camera.projection)))
        sum.reset();
      const int pass = sum ? sum->passes : 0;
      status_.activity = "ground truth: pass " + std::to_string(pass + 1);
      status_.busy = true;
      lock.unlock();
      std::string error;
      try {
        Scene scene = *current->scene;
        scene.camera = camera;
        TruthOptions t;
        t.backend = options_.backend;
        t.spp = 2;
        t.seed = uint64_t(pass) + 1;  // independent passes
        t.axial_map = current->options.axial_map;
        const TruthRenderOutput out = truth_scene(scene, t);
        if (!sum) {
          sum = TruthFrame{};
          sum->mean = out.image;
          sum->variance = out.variance;
          for (float& v : sum->mean.pixels) v = 0;
          for (float& v : sum->variance.pixels) v = 0;
          sum->camera = camera;
          sum->version = version;
        }
        // Running mean of equal passes; the variance of the mean of K passes is sum(var_k) / K^2.
        const int k = pass + 1;
        for (size_t i = 0; i < sum->mean.pixels.size(); ++i) {
          sum->mean.pixels[i] += (out.image.pixels[i] - sum->mean.pixels[i]) / float(k);
          const double var_sum = double(sum->variance.pixels[i]) * (k - 1) * (k - 1) + out.variance.pixels[i];
          sum->variance.pixels[i] = float(var_sum / (double(k) * k));
        }
        sum->passes = k;
        sum->spp = 2 * k;
        double total = 0, var = 0;
        for (size_t i = 0; i < sum->mean.pixels.size(); ++i) {
          total += sum->mean.pixels[i];
          var += sum->variance.pixels[i];
        }
        sum->noise = total > 0 ? std::sqrt(var) / total : 0;
      } catch (const std::exception& e) {
        error = e.what();
      }
      lock.lock();
      if (!error.empty()) {
        status_.error = "ground truth: " + error;
        truth_on_ = false;
      } else if (truth_on_ && version == baked_version_) {
        truth_ = std::move(sum);
      }
    } else if (wanted_version_ != baked_version_) {
      const uint64_t version = wanted_version_;
      const SceneSource source = source_;
      const std::shared_ptr<const Scene> previous = latest_scene_;
      const std::shared_ptr<const Baked> reuse = baked_;
      const std::shared_ptr<const AxialMap> painted = painted_;
      status_.activity = "baking (" + why_ + ")";
      status_.busy = true;
      lock.unlock();
      std::shared_ptr<Baked> fresh;
      std::string error;
      const auto t0 = std::chrono::steady_clock::now();
      try {
        std::shared_ptr<const Scene> scene =
            version == 1 ? previous : std::make_shared<const Scene>(source.load_reusing(*previous));
        RenderOptions o;
        o.backend = options_.backend;
        o.table_photons = options_.table_photons;
        o.smooth_step = options_.smooth_step;
        o.axial_map = painted;
        fresh = std::make_shared<Baked>(scene, o, reuse.get(), options_.preview_coarsening);
      } catch (const std::exception& e) {
        error = e.what();
      }
      const double seconds = seconds_since(t0);
      lock.lock();
      if (fresh) {
        baked_ = std::move(fresh);
        latest_scene_ = baked_->scene;
        good = source;
        status_.error.clear();
        status_.bake_seconds = seconds;
        status_.report = baked_->spectral ? baked_->spectral->report : baked_->prepared.report;
        status_.version = version;
        rendered_request_ = 0;  // the current view again, from the new bake
      } else {
        // The edit is undone: the scene stays the last one that worked.
        status_.error = error + " (edit undone)";
        if (version == wanted_version_) source_ = good;
      }
      baked_version_ = version;
    } else {
      const CameraSettings camera = *wanted_camera_;
      const bool preview = wanted_preview_;
      const uint64_t request = wanted_request_;
      const uint64_t version = baked_version_;
      const std::shared_ptr<const Baked> current = baked_;
      status_.activity = "rendering " + std::to_string(camera.width) + "x" + std::to_string(camera.height);
      status_.busy = true;
      lock.unlock();
      Frame frame;
      std::string error;
      const auto t0 = std::chrono::steady_clock::now();
      try {
        RenderOutput out = current->render(camera, preview);
        frame.image = std::move(out.image);
        frame.metadata = std::move(out.metadata);
        frame.report = std::move(out.report);
        frame.camera = camera;
        frame.preview = preview;
        frame.request = request;
        frame.version = version;
      } catch (const std::exception& e) {
        error = e.what();
      }
      frame.seconds = seconds_since(t0);
      lock.lock();
      if (error.empty()) {
        status_.frame_seconds = frame.seconds;
        truth_camera_ = camera;
        truth_.reset();  // a new view or a new bake: the truth starts again
        frame_ = std::move(frame);
      } else {
        status_.error = error;
      }
      rendered_request_ = request;
    }
    working_ = false;
    const bool more = wanted_version_ != baked_version_ || (wanted_camera_ && baked_ && wanted_request_ != rendered_request_) ||
                      (truth_on_ && truth_ && truth_->passes < kTruthPasses);
    if (!more) {
      status_.activity = "idle";
      status_.busy = false;
    }
    done_.notify_all();
  }
}

}  // namespace nebula::viewer
