#pragma once
// The viewer without its window: the scene being edited (a scene file's text
// and the overrides the edits made, so "save scene" writes TOML that `nebula
// render` reproduces exactly), and a worker thread that re-bakes after an edit
// and renders the views asked for, so the interface never waits: it shows the
// previous frame until the new one is ready, and the status says what is
// being recomputed and why.
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "axial/axial_brush.h"
#include "pipeline/render_scene.h"

namespace nebula::viewer {

// A scene file's text (or the built-in demo's, scenes/demo.toml) and the
// KEY=VALUE overrides of the edits, in order; a key set again moves to the end
// with its new value.
class SceneSource {
 public:
  static SceneSource from_file(const std::string& path);  // Error naming the file when unreadable
  static SceneSource demo();                              // scenes/demo.toml as built in ("demo")
  SceneSource(std::string text, std::string name, std::string base_dir)
      : text_(std::move(text)), name_(std::move(name)), base_dir_(std::move(base_dir)) {}

  void set(const std::string& key, const std::string& value);
  void unset(const std::string& key);
  std::vector<std::string> overrides() const;  // "KEY=VALUE"
  const std::string& name() const { return name_; }
  const std::string& base_dir() const { return base_dir_; }

  Scene load() const;
  Scene load_reusing(const Scene& previous) const;  // keeps previous's grids when unchanged

 private:
  std::string text_, name_, base_dir_;
  std::vector<std::pair<std::string, std::string>> overrides_;
};

// TOML text of a value for an override: a vector as [x, y, z] with floats
// written to round-trip (9 significant digits), numbers %.17g.
std::string toml_vec3(Vec3 v);
std::string toml_number(double v);
// A list of names as a TOML array of strings, e.g. ["sdss_g", "V"] (Error for a
// name holding a quote, a backslash or a line break).
std::string toml_strings(const std::vector<std::string>& values);

// The view as overrides of the scene (camera.*, display.*, and the recorded
// keyframes as animation.keyframes when there are two or more), so that the
// scene saved renders what the viewer shows.
void set_view_overrides(SceneSource& source, const CameraSettings& camera, const DisplaySettings& display,
                        const std::vector<CameraKeyframe>& keys);

struct ViewerOptions {
  Backend backend = Backend::Cpu;
  uint64_t table_photons = 30000;  // photons per row of tables generated on first use
  float smooth_step = 0;           // 0: the exact traversal
  // Previews (Session::request with preview) come from the grid halved this
  // many times, baked on its own after each bake of the full grid (0: the
  // full grid). Scenes using the pyramid keep their grid.
  int preview_coarsening = 0;
};

struct Frame {
  Image image;             // science pixels (radiance)
  ImageMetadata metadata;  // as render_prepared gives it
  RunReport report;        // the render's, with the bakes it was rendered from (their times as baked)
  CameraSettings camera;   // the view, at the size rendered
  bool preview = false;    // the quick frame of a moving camera (Session::request)
  double seconds = 0;      // rendering it
  uint64_t request = 0;    // the request it answers
  uint64_t version = 0;    // the scene version it shows
};

// The ground truth accumulated for one view while the camera rests: the mean
// of equal passes of the path tracer (`nebula truth`, 2 samples per pixel and
// band each, seeds 1, 2, ...) and the variance of that mean.
struct TruthFrame {
  Image mean, variance;
  CameraSettings camera;
  int passes = 0, spp = 0;  // spp: samples per pixel and band so far
  double noise = 0;         // relative standard error of the image's total: sqrt(sum var) / sum mean
  uint64_t version = 0;
};

struct SessionStatus {
  std::string activity = "starting";  // "baking (dust.albedo changed)", "rendering 256x256", "idle"
  std::string error;                  // the last failed edit's one-line error (its scene was kept)
  double bake_seconds = 0;            // the last bake
  double frame_seconds = 0;           // the last frame
  RunReport report;                   // of the last bake and frame
  uint64_t version = 0;               // of the scene baked
  bool busy = false;
};

// A brush stroke on an axial scene's map (axial/axial_brush.h): the brush and
// its dabs in texel coordinates, painted in order (Session::paint sets
// brush.n_bands to the scene's bands).
struct Stroke {
  Brush brush;
  std::vector<BrushPoint> dabs;
};

// The plane a name paints: "tau_v", or one of the scene's band names (its
// emission). Error "<option>: plane '<name>' is not tau_v or one of the
// scene's bands (B, V, R)".
BrushPlane brush_plane(const Scene& scene, const std::string& name, const std::string& option);

// The datasets of a saved map (reconstruct/map_file.cpp's format, the one
// `[axial] file` reads): "tau_v" and "emission_<band>".
constexpr const char* kMapEmissionPrefix = "emission_";

class Session {
 public:
  // Loads the scene now (Error on a bad one) and starts baking it in the background.
  Session(SceneSource source, const ViewerOptions& options);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // The scene as loaded at start or by the last finished edit (for the interface's values).
  const Scene& scene() const { return *shown_scene_; }
  // Sets a scene key; the worker loads, re-bakes and renders again. `why` names
  // the change in the status ("dust.albedo changed"). Camera and display keys
  // belong to the front end and need no bake.
  void edit(const std::string& key, const std::string& value);
  // A [spectral] scene's filters, one per plane (the Filters panel): the edit
  // of `bands`. When they lie within the wavelength range of the basis shown,
  // that range is kept as spectral.range_um (an override, so the scene saved
  // renders the same image) and the worker puts the filters on the prepared
  // basis without baking again (prepare_spectral's `previous`); outside it,
  // the range this made goes and the scene is prepared afresh. A range the
  // scene itself sets is left alone. Error for an unknown filter (no change).
  void set_filters(const std::vector<std::string>& bands);
  // Render this view next; a newer request replaces it. preview: the quick
  // frame for a moving camera (each voxel's light taken once per view,
  // MarchMode::voxel_sources; axial and spectral scenes render as usual).
  void request(const CameraSettings& camera, bool preview = false);
  std::optional<Frame> take_frame();           // the newest finished frame, once
  // Ground truth: while on and nothing else is pending, the worker adds path-tracer
  // passes for the last view rendered; a new view or edit starts again.
  void set_truth(bool on);
  std::optional<TruthFrame> truth() const;  // the accumulation so far, if any
  SessionStatus status() const;
  bool idle() const;  // nothing pending or running
  void wait_idle() const;
  // The source with its overrides, for saving.
  SceneSource source() const;
  // The bake frames come from, shared so the window's thread can render from it
  // on the GPU (viewer/gpu_frame.h); null before the first bake, for an axial
  // scene and for the pyramid (rendered by the session only).
  std::shared_ptr<const PreparedGrid> prepared() const;
  // Refreshes scene() after an edit finished (main thread; cheap when nothing changed).
  void sync_scene();
  // The scene as shown, with this view, as a TOML file `nebula render` reproduces:
  // its resolved text with a comment line in front. Error once the map was
  // painted or loaded (save_scene writes the map beside the scene then).
  std::string saved_scene_text(const CameraSettings& camera, const DisplaySettings& display,
                               const std::vector<CameraKeyframe>& keys) const;

  // The axial map (an [axial] scene only; Error otherwise): the painted or
  // loaded one, else the scene's own as the renderer builds it (main thread).
  std::shared_ptr<const AxialMap> axial_map();
  // Paints a stroke on a copy of the map and renders the scene with it (the
  // worker re-renders in the background, the previous frame shown meanwhile).
  // Error naming the brush's field for a bad brush, or for a scene that is
  // not axial; the map is unchanged then.
  PaintResult paint(Stroke stroke);
  // Replaces the map by an HDF5 file's (tau_v, and emission_<band> for every
  // band when the file has them), placed by the scene's axial.length_pc,
  // origin and axis. Error naming the file; nothing changes then.
  void load_map(const std::string& path);
  // Writes the map as load_map and `[axial] file` read it (written aside, then renamed).
  void save_map(const std::string& path, bool overwrite);
  bool map_edited() const;  // painted or loaded since the scene's own map
  void revert_map();        // back to the scene's own map

 private:
  struct Baked;
  void work();

  ViewerOptions options_;
  mutable std::mutex mutex_;
  mutable std::condition_variable wake_, done_;
  SceneSource source_;
  uint64_t wanted_version_ = 1, baked_version_ = 0;
  std::string why_ = "the scene was opened";
  std::string kept_range_;  // the spectral.range_um override set_filters made ("" for none)
  std::optional<CameraSettings> wanted_camera_;
  bool wanted_preview_ = false;
  uint64_t wanted_request_ = 0, rendered_request_ = 0;
  bool working_ = false, stop_ = false;
  std::shared_ptr<Baked> baked_;                   // replaced by the worker only
  std::shared_ptr<const Scene> latest_scene_;      // set by the worker, taken by sync_scene
  std::shared_ptr<const Scene> shown_scene_;       // the main thread's
  std::optional<Frame> frame_;
  bool truth_on_ = false;
  std::optional<CameraSettings> truth_camera_;  // the last view rendered
  std::optional<TruthFrame> truth_;
  std::shared_ptr<const AxialMap> painted_;          // set: rendered instead of the scene's map
  std::shared_ptr<const AxialMap> built_;            // the scene's own map, for painting (main thread)
  std::shared_ptr<const Scene> built_for_;           // the scene built_ was built from
  SessionStatus status_;
  std::thread thread_;
};

// Writes the scene as the viewer shows it to `path` (TOML, written aside and
// renamed; `nebula render` reproduces the view). With the map painted or
// loaded, the map goes first to PATH's stem + ".map.h5" beside it, and the
// scene's [axial] table reads it (scene_text_with_axial_file). Returns the
// files written. Errors name the file; nothing is written for a refused target.
std::vector<std::string> save_scene(Session& session, const CameraSettings& camera, const DisplaySettings& display,
                                    const std::vector<CameraKeyframe>& keys, const std::string& path, bool force);

}  // namespace nebula::viewer
