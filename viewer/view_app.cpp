// nebula-view: the interactive viewer (GLFW, Dear ImGui, OpenGL 3.3). Opens a
// scene file or the built-in demo; fly and orbit navigation; the three camera
// kinds; live edits of the dust, the stars, the multiple-scattering mode and
// the display, re-baked in the background (viewer/viewer_session.h) while the
// previous frame stays on screen; a reduced resolution while the camera moves,
// the full one when it rests; screenshots, "save scene" and keyframes; for an
// axial scene, the 2D map painted with a brush (Khalass 2021 section 4.1),
// loaded and saved. An automation mode (--frames N --set KEY=VALUE --paint
// x,r,radius,value --screenshot F) runs the real window and interface for
// tests and scripted pictures.
#define GL_GLEXT_PROTOTYPES  // buffer objects (OpenGL 1.5+) from Mesa's or NVIDIA's libGL
#define GLFW_INCLUDE_GLEXT
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/gpu.h"
#include "illumination/filters.h"
#include "imageio/image_output.h"
#include "viewer/display_image.h"
#include "viewer/gpu_frame.h"
#include "viewer/navigation.h"
#include "viewer/viewer_session.h"

namespace nebula::viewer {
namespace {

using Clock = std::chrono::steady_clock;

struct Args {
  std::string scene, backend = "auto", screenshot, window_shot, save_scene;
  std::vector<std::string> sets;
  std::vector<std::string> paints;  // "x,r,radius,value[,plane]"
  std::string brush_shape = "round", brush_mode = "set", load_map, save_map;
  std::string paint_drag;  // "x0,r0,x1,r1,radius,value": a mouse drag on the paint panel (automation)
  bool brush_soft = false;
  int frames = 0;  // 0: interactive
  int window_width = 1280, window_height = 800;
  int preview_scale = 0;       // 0: 2 on the CPU, 1 on the GPU
  long long preview_photons = -1;  // -1: 65536 on the CPU, the scene's on the GPU
  bool force = false, show_panels = false;
  bool exact_preview = false;  // moving frames marched exactly too (default: voxel sources)
  int preview_coarsening = -1;  // -1: 1 on the CPU, 0 on the GPU
  std::string table_photons = "30000";
};

// ------------------------------------------------------------ values of --set

bool parse_number(const std::string& text, double& out) {
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == 0 && std::isfinite(out);
}

bool parse_vec3(const std::string& text, Vec3& out) {
  double v[3];
  if (std::sscanf(text.c_str(), " [ %lf , %lf , %lf ] ", &v[0], &v[1], &v[2]) != 3) return false;
  out = Vec3{float(v[0]), float(v[1]), float(v[2])};
  return true;
}

std::string unquote(std::string s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

// What the front end owns: the view and the display. Everything else is the session's.
struct View {
  CameraSettings camera, home;
  DisplaySettings display;
  bool orbit_mode = true;
  double speed = 0.5;  // pc per second when flying
  std::vector<CameraKeyframe> keys;
  double key_spacing = 2.0;  // seconds between recorded keyframes
};

// Applies a camera.* or display.* KEY=VALUE to the view; false for other keys.
// Throws Error naming the key for a value it cannot take.
bool set_view(View& v, const std::string& key, const std::string& value) {
  auto bad = [&](const std::string& what) { throw Error("--set " + key + ": '" + value + "' is not " + what); };
  double x = 0;
  Vec3 p;
  if (key == "camera.position" || key == "camera.look_at" || key == "camera.up") {
    if (!parse_vec3(value, p)) bad("[x, y, z]");
    (key == "camera.position" ? v.camera.position : key == "camera.look_at" ? v.camera.look_at : v.camera.up) = p;
  } else if (key == "camera.fov_deg" || key == "camera.exposure" || key == "camera.ortho_width") {
    if (!parse_number(value, x)) bad("a number");
    (key == "camera.fov_deg" ? v.camera.fov_deg : key == "camera.exposure" ? v.camera.exposure : v.camera.ortho_width) = x;
  } else if (key == "camera.width" || key == "camera.height") {
    if (!parse_number(value, x) || x != std::floor(x)) bad("a whole number");
    (key == "camera.width" ? v.camera.width : v.camera.height) = int(x);
  } else if (key == "camera.kind") {
    if (!parse_projection(unquote(value), v.camera.projection)) bad("perspective, orthographic or fisheye");
  } else if (key == "display.stretch") {
    if (!parse_stretch(unquote(value), v.display.stretch)) bad("linear, asinh or log");
  } else if (key == "display.auto_exposure") {
    if (value != "true" && value != "false") bad("true or false");
    v.display.auto_exposure = value == "true";
  } else if (key == "display.percentile" || key == "display.white" || key == "display.softening") {
    if (!parse_number(value, x) || !(x > 0)) bad("a positive number");
    (key == "display.percentile" ? v.display.percentile : key == "display.white" ? v.display.white : v.display.softening) = x;
  } else {
    return false;
  }
  return true;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> fields;
  for (size_t begin = 0;;) {
    const size_t comma = text.find(',', begin);
    fields.push_back(text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
    if (comma == std::string::npos) return fields;
    begin = comma + 1;
  }
}

// One --paint: "x,r,radius,value[,plane]" (texels, texels, texels, the
// value, tau_v or a band name; tau_v when left out) with the --brush-* options
// (checked before). Error naming the option for a wrong number of fields, a
// field that is not a number, or a plane the scene does not have.
Stroke parse_paint(const std::string& text, const Scene& scene, const Args& args) {
  const std::string option = "--paint '" + text + "'";
  const std::vector<std::string> fields = split_commas(text);
  if (fields.size() != 4 && fields.size() != 5)
    throw Error(option + ": expected x,r,radius,value[,plane] (texels, texels, texels, value, tau_v or a band), got " +
                std::to_string(fields.size()) + " field(s)");
  double v[4];
  const char* names[] = {"x", "r", "radius", "value"};
  for (int i = 0; i < 4; ++i)
    if (!parse_number(fields[size_t(i)], v[i])) throw Error(option + ": " + names[i] + " '" + fields[size_t(i)] + "' is not a number");
  if (!scene.axial) throw Error(option + ": the scene has no [axial] map to paint");
  Stroke stroke;
  parse_brush_shape(args.brush_shape, stroke.brush.shape);
  parse_brush_mode(args.brush_mode, stroke.brush.mode);
  stroke.brush.soft = args.brush_soft;
  stroke.brush.radius = float(v[2]);
  stroke.brush.value = float(v[3]);
  stroke.brush.plane = brush_plane(scene, fields.size() == 5 ? fields[4] : "tau_v", option);
  stroke.dabs.push_back({float(v[0]), float(v[1])});
  return stroke;
}

void write_screenshot(const Frame& frame, const View& view, const std::string& path, bool force) {
  ImageMetadata m = frame.metadata;
  m.display = view.display;
  m.exposure = view.camera.exposure;
  write_image(frame.image, path, m, force);
}

// The same view and size (exposure aside: a display setting).
bool same_view(const CameraSettings& a, const CameraSettings& b) {
  auto same = [](Vec3 p, Vec3 q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
  return a.projection == b.projection && same(a.position, b.position) && same(a.look_at, b.look_at) &&
         same(a.up, b.up) && a.fov_deg == b.fov_deg && a.ortho_width == b.ortho_width && a.width == b.width &&
         a.height == b.height;
}

// ------------------------------------------------------------ the window

struct Texture {
  GLuint id = 0;
  int width = 0, height = 0;
  void upload(const Rgba8& rgba) {
    if (id == 0) glGenTextures(1, &id);
    glBindTexture(GL_TEXTURE_2D, id);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgba.width, rgba.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.pixels.data());
    width = rgba.width;
    height = rgba.height;
  }
};

// The largest rectangle of the image's aspect in the window, centred; 1:1 when it fits exactly.
void image_rect(int win_w, int win_h, int img_w, int img_h, float& x, float& y, float& w, float& h) {
  const float s = std::fmin(float(win_w) / img_w, float(win_h) / img_h);
  w = img_w * s;
  h = img_h * s;
  x = std::floor((win_w - w) / 2);
  y = std::floor((win_h - h) / 2);
}

bool window_shot(GLFWwindow* window, const std::string& path) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  std::vector<uint8_t> pixels(size_t(w) * h * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  std::vector<uint8_t> flipped(pixels.size());
  for (int y = 0; y < h; ++y)
    std::copy_n(pixels.begin() + std::ptrdiff_t(size_t(h - 1 - y) * w * 4), size_t(w) * 4,
                flipped.begin() + std::ptrdiff_t(size_t(y) * w * 4));
  return stbi_write_png(path.c_str(), w, h, 4, flipped.data(), w * 4) != 0;
}

int run(const Args& args) {
  Backend backend = Backend::Cpu;
  if (args.backend == "cuda" || args.backend == "gpu") {
    std::string why;
    if (!gpu_available(&why)) throw Error("--backend: cuda requested but " + why);
    backend = Backend::Cuda;
  } else if (args.backend == "auto") {
    backend = gpu_available() ? Backend::Cuda : Backend::Cpu;
  } else if (args.backend != "cpu") {
    throw Error("--backend: expected cpu, cuda or auto, got '" + args.backend + "'");
  }
  if (args.frames < 0) throw Error("--frames: must be >= 0");
  for (const std::string& out : {args.screenshot, args.save_scene, args.window_shot, args.save_map})
    if (!out.empty()) check_output_target(out, args.force, "folder", true);
  if (!args.screenshot.empty()) check_image_format(args.screenshot);
  const bool automation = args.frames > 0;

  SceneSource source = args.scene.empty() ? SceneSource::demo() : SceneSource::from_file(args.scene);
  // The CPU bakes the diffuse field with fewer photons unless told otherwise (recorded in the
  // scene, so a saved scene renders what the viewer showed).
  const long long photons = args.preview_photons >= 0 ? args.preview_photons : (backend == Backend::Cpu ? 65536 : 0);
  View view;
  std::vector<std::pair<std::string, std::string>> scene_sets;
  for (const std::string& set : args.sets) {
    const size_t eq = set.find('=');
    if (eq == std::string::npos || eq == 0) throw Error("--set: expected KEY=VALUE, got '" + set + "'");
    scene_sets.emplace_back(set.substr(0, eq), set.substr(eq + 1));
  }
  if (photons > 0) source.set("render.diffuse_photons", std::to_string(photons));
  // Scene keys go to the scene before it is first loaded: one bake, and bad ones refused up front.
  std::vector<std::pair<std::string, std::string>> view_sets;
  for (const auto& [key, value] : scene_sets)
    if (key.rfind("camera.", 0) == 0 || key.rfind("display.", 0) == 0)
      view_sets.emplace_back(key, value);
    else
      source.set(key, value);

  ViewerOptions options;
  options.backend = backend;
  options.preview_coarsening = args.preview_coarsening >= 0 ? args.preview_coarsening : (backend == Backend::Cpu ? 1 : 0);
  {
    double photons = 0;
    if (!parse_number(args.table_photons, photons) || !(photons >= 1000 && photons <= 1e9) || photons != std::floor(photons))
      throw Error("--table-photons: expected a whole number from 1000 to 1e9, got '" + args.table_photons + "'");
    options.table_photons = uint64_t(photons);
  }
  Session session(std::move(source), options);
  view.camera = view.home = session.scene().camera;
  view.display = session.scene().display;
  for (const auto& [key, value] : view_sets) set_view(view, key, value);
  if (auto issue = camera_issue(view.camera)) throw Error("--set: camera." + issue->field + ": " + issue->reason);
  const int preview_scale = args.preview_scale > 0 ? args.preview_scale : (backend == Backend::Cpu ? 2 : 1);
  {
    BrushShape shape;
    BrushMode mode;
    if (!parse_brush_shape(args.brush_shape, shape))
      throw Error("--brush-shape: expected round or square, got '" + args.brush_shape + "'");
    if (!parse_brush_mode(args.brush_mode, mode))
      throw Error("--brush-mode: expected set, add or erase, got '" + args.brush_mode + "'");
  }
  // The map: loaded, then the scripted strokes, all checked before the first is painted.
  if (!args.load_map.empty()) session.load_map(args.load_map);
  std::vector<Stroke> strokes;
  for (const std::string& p : args.paints) strokes.push_back(parse_paint(p, session.scene(), args));
  for (size_t i = 0; i < strokes.size(); ++i) {
    try {
      session.paint(strokes[i]);
    } catch (const Error& e) {
      throw Error("--paint '" + args.paints[i] + "': " + e.what());
    }
  }
  if (!args.save_map.empty() && !session.scene().axial) throw Error("--save-map: the scene has no [axial] map");
  // A scripted mouse drag over the paint panel's map image (the interface's own painting path).
  std::vector<double> drag;
  if (!args.paint_drag.empty()) {
    const std::string option = "--paint-drag '" + args.paint_drag + "'";
    for (const std::string& field : split_commas(args.paint_drag)) {
      double v = 0;
      if (!parse_number(field, v)) throw Error(option + ": '" + field + "' is not a number (x0,r0,x1,r1,radius,value)");
      drag.push_back(v);
    }
    if (drag.size() != 6) throw Error(option + ": expected x0,r0,x1,r1,radius,value, got " + std::to_string(drag.size()) + " field(s)");
    if (!session.scene().axial) throw Error(option + ": the scene has no [axial] map to paint");
    if (!automation || !args.show_panels) throw Error(option + ": needs --frames and --show-panels (it drags on the panel)");
  }

  if (!glfwInit()) throw Error("nebula-view: cannot start GLFW (no display? under CI run it with xvfb-run)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  // Automation shows the image 1:1 (the window's pixels are then the image's), unless the interface is wanted.
  const bool one_to_one = automation && !args.show_panels;
  const int win_w = one_to_one ? view.camera.width : args.window_width;
  const int win_h = one_to_one ? view.camera.height : args.window_height;
  GLFWwindow* window = glfwCreateWindow(win_w, win_h, ("nebula-view: " + session.source().name()).c_str(), nullptr, nullptr);
  if (!window) {
    glfwTerminate();
    throw Error("nebula-view: cannot open an OpenGL 3.3 window");
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(automation ? 0 : 1);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330");

  Texture texture;
  // With CUDA, the interactive frame is rendered and tone-mapped on the GPU into a pixel buffer
  // OpenGL reads (no host round trip); the session's host frames serve screenshots and auto exposure.
  // Automation keeps to the host frames: its window must equal the screenshot bit for bit.
  std::unique_ptr<GpuFrame> gpu;
  if (backend == Backend::Cuda && GpuFrame::available() && !automation) gpu = std::make_unique<GpuFrame>();
  GLuint pbo = 0;
  size_t pbo_bytes = 0;
  CameraSettings gpu_camera{};
  DisplaySettings gpu_display;
  double gpu_exposure = -1, gpu_ms = 0;
  uint64_t gpu_version = 0;
  bool gpu_shown = false, gpu_preview = false;  // gpu_preview: the shown GPU frame is a moving camera's
  std::optional<Frame> full;  // the last full-resolution frame of the current view
  std::optional<Frame> shown;
  Rgba8 shown_rgba;
  CameraSettings requested{};
  bool have_request = false, requested_preview = false;
  uint64_t version_seen = 0;
  auto last_motion = Clock::now() - std::chrono::seconds(10);
  char screenshot_path[512] = "nebula-view.png", scene_path[512] = "nebula-view.toml";
  std::string message;
  int frames = 0;
  bool hide_panels = false, last_frame_with_panels = false, last_frame_with_panels_drawn = false;
  bool truth_on = false, show_truth = false;
  int truth_shown_passes = -1;
  const char* kinds[] = {"perspective", "orthographic", "fisheye"};
  const char* stretches[] = {"linear", "asinh", "log"};
  const char* modes[] = {"diffuse", "pyramid", "none"};
  // The paint panel's state (an axial scene only).
  Texture map_texture;
  std::shared_ptr<const AxialMap> map_shown;
  int map_plane = 0, brush_shape = 0, brush_mode = 0;  // plane 0: tau_v, b + 1: band b's emission
  int map_plane_shown = -1;
  float map_max = 0, brush_radius = 6, brush_value = 1;
  bool brush_soft = args.brush_soft;
  brush_shape = args.brush_shape == "square" ? 1 : 0;
  brush_mode = args.brush_mode == "add" ? 1 : args.brush_mode == "erase" ? 2 : 0;
  if (!drag.empty()) brush_radius = float(drag[4]), brush_value = float(drag[5]);
  BrushPoint last_dab;
  char map_path[512] = "painted.map.h5";
  // The map image's place on screen, for --paint-drag: press at the start, kDragSteps moves, release.
  constexpr int kDragSteps = 8;
  ImVec2 map_at{0, 0}, map_size{0, 0};
  int drag_step = drag.empty() ? -1 : 0, map_frames = 0;
  int total_frames = args.frames;
  auto edit = [&](const std::string& key, const std::string& value) { session.edit(key, value); };

  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    if (automation) session.wait_idle();  // every automated frame shows a finished render
    session.sync_scene();
    const Scene& scene = session.scene();
    const SessionStatus status = session.status();

    // Navigation (not while the interface has the mouse or keyboard).
    const auto now = Clock::now();
    static auto last_time = now;
    const double dt = std::chrono::duration<double>(now - last_time).count();
    last_time = now;
    CameraSettings before = view.camera;
    if (!io.WantCaptureMouse) {
      const ImVec2 d = io.MouseDelta;
      const double turn = 0.005;
      if (ImGui::IsMouseDown(ImGuiMouseButton_Left) && !io.KeyCtrl && (d.x != 0 || d.y != 0))
        view.camera = view.orbit_mode ? orbit(view.camera, -d.x * turn, d.y * turn) : fly_turn(view.camera, -d.x * turn, -d.y * turn);
      if (ImGui::IsMouseDown(ImGuiMouseButton_Right) && (d.x != 0 || d.y != 0))
        view.camera = fly_turn(view.camera, -d.x * turn, -d.y * turn);
      if (io.MouseWheel != 0) view.camera = dolly(view.camera, std::pow(0.9, io.MouseWheel));
      // Ctrl + drag moves the first star in the view's plane (applied on release: it needs a bake).
      if (!scene.stars.empty() && io.KeyCtrl && ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
        const ImVec2 drag = ImGui::GetMouseDragDelta(ImGuiMouseButton_Left, 0.0f);
        if (drag.x != 0 || drag.y != 0) {
          const Camera cam = make_camera(view.camera);
          const Vec3 star = scene.stars[0].position;
          const float dist = length(star - view.camera.position);
          const float per_pixel = 2.0f * dist * float(std::tan(view.camera.fov_deg * 3.14159265 / 360)) / float(win_h);
          const Vec3 moved = star + (drag.x * per_pixel) * cam.right - (drag.y * per_pixel) * cam.up;
          edit("stars.0.position", toml_vec3(moved));
        }
      }
    }
    static bool r_was_down = false;
    const bool r_down = glfwGetKey(window, GLFW_KEY_R) == GLFW_PRESS;
    if (!io.WantCaptureKeyboard) {
      auto down = [&](int key) { return glfwGetKey(window, key) == GLFW_PRESS; };
      const double step = view.speed * dt * (io.KeyShift ? 4 : 1);
      double f = 0, r = 0, u = 0;
      if (down(GLFW_KEY_W)) f += step;
      if (down(GLFW_KEY_S)) f -= step;
      if (down(GLFW_KEY_D)) r += step;
      if (down(GLFW_KEY_A)) r -= step;
      if (down(GLFW_KEY_E)) u += step;
      if (down(GLFW_KEY_Q)) u -= step;
      if (f != 0 || r != 0 || u != 0) view.camera = fly_move(view.camera, f, r, u);
      if (r_down && !r_was_down) view.camera = view.home;
    }
    r_was_down = r_down;
    if (!same_view(before, view.camera)) last_motion = now;

    // What to render: a reduced size while the camera moves, the full one when it rests.
    const bool moving = !automation && std::chrono::duration<double>(now - last_motion).count() < 0.3;
    const bool host_frames = !gpu_shown || !moving;  // with the GPU showing, host frames only at rest
    CameraSettings want = view.camera;
    want.exposure = 1;  // display only
    if (moving && preview_scale > 1) {
      want.width = std::max(1, view.camera.width / preview_scale);
      want.height = want.projection == Projection::Fisheye ? want.width : std::max(1, view.camera.height / preview_scale);
    }
    if (gpu_shown) want = view.camera, want.exposure = 1;  // full size: the GPU shows the moving frames
    // A moving camera's host frames are previews (each voxel's light once per view); at rest, exact.
    const bool preview = moving && !gpu_shown && !args.exact_preview;
    if (host_frames && !camera_issue(want) &&
        (!have_request || !same_view(want, requested) || preview != requested_preview || status.version != version_seen)) {
      session.request(want, preview);
      requested = want;
      requested_preview = preview;
      have_request = true;
      version_seen = status.version;
    }
    // The GPU frame: every change of view, display or scene, at full size.
    std::shared_ptr<const PreparedGrid> prepared = gpu ? session.prepared() : nullptr;
    gpu_shown = gpu_shown && prepared != nullptr;
    if (prepared && !camera_issue(view.camera)) {
      const double exposure = view.display.auto_exposure && shown_rgba.exposure > 0 ? shown_rgba.exposure : view.camera.exposure;
      CameraSettings c = view.camera;
      c.exposure = 1;
      // A moving camera's GPU frames are previews too (each voxel's light once per view, at full
      // size); the exact frame follows when the camera rests.
      const bool want_preview = moving && !args.exact_preview;
      if (!gpu_shown || !same_view(c, gpu_camera) || !(gpu_display == view.display) || gpu_exposure != exposure ||
          gpu_version != status.version || gpu_preview != want_preview) {
        const size_t bytes = size_t(c.width) * c.height * 4;
        if (pbo == 0) glGenBuffers(1, &pbo);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo);
        if (bytes > pbo_bytes) {
          glBufferData(GL_PIXEL_UNPACK_BUFFER, GLsizeiptr(bytes), nullptr, GL_STREAM_DRAW);
          pbo_bytes = bytes;
        }
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        try {
          RenderInputs in = prepared->inputs;
          in.camera = make_camera(c);
          in.exposure = 1.0f;
          in.mode.voxel_sources = want_preview;
          gpu_ms = 1e3 * gpu->render_to_gl(in, exposure, view.display, pbo);
          gpu_preview = want_preview;
          if (texture.id == 0) glGenTextures(1, &texture.id);
          glBindTexture(GL_TEXTURE_2D, texture.id);
          glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
          glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
          glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo);
          glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
          glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, c.width, c.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
          glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
          texture.width = c.width;
          texture.height = c.height;
          gpu_camera = c;
          gpu_display = view.display;
          gpu_exposure = exposure;
          gpu_version = status.version;
          gpu_shown = true;
        } catch (const std::exception& e) {
          message = std::string("GPU frame: ") + e.what() + "; showing the session's frames";
          gpu.reset();
          gpu_shown = false;
        }
      }
    }
    bool new_pixels = false;
    if (std::optional<Frame> f = session.take_frame()) {
      if (f->camera.width == view.camera.width && f->camera.height == view.camera.height) full = *f;
      shown = std::move(f);
      new_pixels = true;
    }
    static DisplaySettings shown_display;
    static double shown_exposure = 0;
    if (shown && (new_pixels || !(shown_display == view.display) || shown_exposure != view.camera.exposure)) {
      shown_rgba = display_image(shown->image, view.camera.exposure, view.display, shown->metadata);
      if (!gpu_shown) texture.upload(shown_rgba);
      shown_display = view.display;
      shown_exposure = view.camera.exposure;
    }

    // The ground truth, accumulated by the session while the camera rests, shown instead when asked.
    std::optional<TruthFrame> truth = truth_on ? session.truth() : std::nullopt;
    if (show_truth && truth && !gpu_shown && (truth->passes != truth_shown_passes || new_pixels)) {
      texture.upload(display_image(truth->mean, view.camera.exposure, view.display, shown ? shown->metadata : ImageMetadata{}));
      truth_shown_passes = truth->passes;
    } else if (!show_truth && truth_shown_passes >= 0 && shown) {
      texture.upload(shown_rgba);
      truth_shown_passes = -1;
    }
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    if (drag_step >= 0 && map_frames >= 3 && map_shown) {
      // After the backend's mouse state: the scripted drag replaces it for this frame. The panel
      // has been shown for frames (a new window is hidden in its first, and a press where no
      // window was hovered belongs to the application); the mouse hovers the start one frame
      // before it presses.
      const int k = std::max(0, drag_step - 1);
      const float t = std::min(1.0f, float(k) / kDragSteps);
      const float x = float(drag[0] + t * (drag[2] - drag[0])), r = float(drag[1] + t * (drag[3] - drag[1]));
      io.MousePos = ImVec2(map_at.x + x / float(map_shown->nx) * map_size.x, map_at.y + (1 - r / float(map_shown->nr)) * map_size.y);
      io.MouseDown[0] = drag_step >= 1 && k <= kDragSteps && drag_step <= kDragSteps + 1;
      drag_step = drag_step <= kDragSteps + 1 ? drag_step + 1 : -1;
    }
    if (drag_step >= 0) total_frames = std::max(total_frames, frames + 3);  // the drag finishes first
    ImGui::NewFrame();
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    if (texture.id) {
      float x, y, w, h;
      image_rect(fb_w, fb_h, texture.width, texture.height, x, y, w, h);
      ImGui::GetBackgroundDrawList()->AddImage((ImTextureID)(intptr_t)texture.id, ImVec2(x, y), ImVec2(x + w, y + h));
    }
    if (!hide_panels) {
      ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
      ImGui::SetNextWindowSize(ImVec2(380, 0), ImGuiCond_FirstUseEver);
      ImGui::Begin("nebula-view");
      ImGui::Text("%s on the %s", session.source().name().c_str(), backend == Backend::Cuda ? "GPU (CUDA)" : "CPU");
      if (gpu_shown)
        ImGui::Text("GPU frame %.2f ms (%dx%d, CUDA-OpenGL interop%s); host frame %.1f ms", gpu_ms, texture.width,
                    texture.height, gpu_preview ? ", moving: voxel sources" : "", status.frame_seconds * 1e3);
      else
        ImGui::Text("frame %.1f ms (%dx%d)%s", status.frame_seconds * 1e3, shown ? shown->camera.width : 0,
                    shown ? shown->camera.height : 0, moving ? ", moving: reduced size" : "");
      ImGui::Text("bake %.2f s; %s", status.bake_seconds, status.activity.c_str());
      if (!status.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", status.error.c_str());
      if (!message.empty()) ImGui::TextWrapped("%s", message.c_str());
      if (ImGui::CollapsingHeader("Computed, and why")) {
        const RunReport& r = status.report;
        for (const BandReport& b : r.bands)
          ImGui::Text("band %s: A/A_V %.4f, albedo %.3g, g %.3g%s", b.name.c_str(), b.extinction_ratio, b.albedo, b.g,
                      b.scatters ? "" : " (no scattering)");
        for (const TableReport& t : r.tables) ImGui::Text("table a=%.3g g=%.3g: %s (%.2f s)", t.albedo, t.g, to_string(t.origin), t.seconds);
        if (r.bake.done) ImGui::Text("bake: %zu star(s) x %llu voxels, %.2f s", r.bake.stars, (unsigned long long)r.bake.cells, r.bake.seconds);
        ImGui::Text("multiple scattering: %s", r.multiple_scattering.c_str());
        if (r.diffuse.done)
          ImGui::Text("diffuse field: %llu photons/band, degree %d, %.2f s", (unsigned long long)r.diffuse.photons_per_band,
                      r.diffuse.order, r.diffuse.wall_seconds);
      }
      if (ImGui::CollapsingHeader("Ground truth")) {
        if (ImGui::Checkbox("accumulate the truth while the camera rests", &truth_on)) session.set_truth(truth_on);
        ImGui::Checkbox("show the truth instead of the fast frame", &show_truth);
        if (truth) {
          ImGui::Text("truth: %d samples per pixel and band, noise %.2f%% (standard error of the total)", truth->spp,
                      100 * truth->noise);
          if (full && full->image.pixels.size() == truth->mean.pixels.size()) {
            double fast = 0, exact = 0;
            for (size_t i = 0; i < truth->mean.pixels.size(); ++i) fast += full->image.pixels[i], exact += truth->mean.pixels[i];
            if (exact > 0)
              ImGui::Text("fast against truth: %+.2f%% +- %.2f%% in total", 100 * (fast - exact) / exact, 100 * truth->noise);
          }
        } else if (truth_on) {
          ImGui::TextDisabled("waiting for the camera to rest");
        }
      }
      if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) {
        int kind = int(view.camera.projection);
        if (ImGui::Combo("kind", &kind, kinds, 3)) {
          view.camera.projection = Projection(kind);
          if (view.camera.projection == Projection::Fisheye) view.camera.height = view.camera.width;
          if (view.camera.projection == Projection::Orthographic && !(view.camera.ortho_width > 0))
            view.camera.ortho_width = length(view.camera.look_at - view.camera.position);
        }
        float fov = float(view.camera.fov_deg);
        if (ImGui::SliderFloat("field of view", &fov, 5, 150, "%.1f deg")) view.camera.fov_deg = fov;
        int mode = view.orbit_mode ? 1 : 0;
        ImGui::RadioButton("orbit", &mode, 1);
        ImGui::SameLine();
        ImGui::RadioButton("fly (WASD, QE)", &mode, 0);
        view.orbit_mode = mode == 1;
        float speed = float(view.speed);
        if (ImGui::SliderFloat("fly speed", &speed, 0.01f, 5, "%.2f pc/s", ImGuiSliderFlags_Logarithmic)) view.speed = speed;
        if (ImGui::Button("reset (R)")) view.camera = view.home;
        ImGui::SameLine();
        if (ImGui::Button("record keyframe")) {
          CameraKeyframe k;
          k.time = view.keys.empty() ? 0 : view.keys.back().time + view.key_spacing;
          k.position = view.camera.position;
          k.look_at = view.camera.look_at;
          k.up = view.camera.up;
          k.fov_deg = view.camera.fov_deg;
          view.keys.push_back(k);
        }
        ImGui::Text("%zu keyframe(s) recorded (saved with the scene)", view.keys.size());
      }
      if (scene.spectral && ImGui::CollapsingHeader("Filters", ImGuiTreeNodeFlags_DefaultOpen)) {
        // The spectral renderer integrates through any filter: each plane's
        // filter, picked from those `nebula filters` lists (put on the prepared
        // basis when it holds them, no bake; docs/spectral.md).
        static const std::vector<FilterInfo> known = known_filters();
        for (size_t b = 0; b < scene.bands.size(); ++b) {
          const std::string label = "plane " + std::to_string(b + 1);
          if (ImGui::BeginCombo(label.c_str(), scene.bands[b].c_str())) {
            for (const FilterInfo& f : known) {
              const bool selected = f.name == scene.bands[b];
              if (ImGui::Selectable(f.name.c_str(), selected) && !selected) {
                std::vector<std::string> bands = scene.bands;
                bands[b] = f.name;
                session.set_filters(bands);  // on the prepared basis when it holds them
              }
              if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", f.source.c_str());
            }
            ImGui::EndCombo();
          }
        }
      }
      if (ImGui::CollapsingHeader("Dust", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t b = 0; b < scene.bands.size(); ++b) {
          float a = float(scene.dust.albedo[b]), g = float(scene.dust.g[b]);
          if (ImGui::SliderFloat(("albedo " + scene.bands[b]).c_str(), &a, 0, 1))
            edit("dust.albedo." + scene.bands[b], toml_number(a));
          if (ImGui::SliderFloat(("g " + scene.bands[b]).c_str(), &g, -0.95f, 0.95f))
            edit("dust.g." + scene.bands[b], toml_number(g));
        }
        float rv = float(scene.dust.R_V);
        if (ImGui::SliderFloat("R_V", &rv, 2, 6)) edit("dust.R_V", toml_number(rv));
        int law = scene.dust.law == ExtinctionLaw::CCM89 ? 0 : 1;
        const char* laws[] = {"ccm89", "odonnell94"};
        if (ImGui::Combo("extinction law", &law, laws, 2)) edit("dust.law", std::string("\"") + laws[law] + "\"");
        // "WHAT: multiply by x0.5 x2 (= 1)": the factor clicked, 0 for "= 1", 1 for none.
        auto scale_buttons = [](const std::string& what, bool with_reset) {
          float factor = 1;
          ImGui::Text("%s: multiply by", what.c_str());
          ImGui::SameLine();
          if (ImGui::Button(("x0.5##" + what).c_str())) factor = 0.5f;
          ImGui::SameLine();
          if (ImGui::Button(("x2##" + what).c_str())) factor = 2.0f;
          if (with_reset) {
            ImGui::SameLine();
            if (ImGui::Button(("= 1##" + what).c_str())) factor = 0.0f;
          }
          return factor;
        };
        const float scale = scale_buttons("density", false);
        if (scale != 1) edit("density.scale", toml_number(scene.density_scale * scale));
        // The emission's scale: [emission]'s for a grid, the map's own for an axial scene.
        if (!scene.emission.empty() || scene.axial) {
          const std::string key = scene.axial ? "axial.emission_scale" : "emission.scale";
          const float factor = scale_buttons("emission", true);
          const double current = scene.axial ? scene.axial->emission_scale : scene.emission_scale;
          if (factor == 0) edit(key, toml_number(1.0));
          else if (factor != 1) edit(key, toml_number(current * factor));
        }
      }
      if (ImGui::CollapsingHeader("Stars", ImGuiTreeNodeFlags_DefaultOpen)) {
        for (size_t i = 0; i < scene.stars.size(); ++i) {
          const SceneStar& s = scene.stars[i];
          ImGui::PushID(int(i));
          ImGui::Text("%s %s", s.name.empty() ? ("star " + std::to_string(i)).c_str() : s.name.c_str(), s.spectral_class.c_str());
          const std::string key = "stars." + std::to_string(i);
          float lum = float(std::log10(s.luminosity_lsun));
          if (ImGui::SliderFloat("log10 L/L_sun", &lum, -2, 7)) edit(key + ".luminosity_lsun", toml_number(std::pow(10.0, lum)));
          // A class or a temperature replaces the star's entry whole (a file's class and temperature must agree).
          auto star_entry = [&](const std::string& kind) {
            return "{name = \"" + s.name + "\", position = " + toml_vec3(s.position) +
                   ", luminosity_lsun = " + toml_number(s.luminosity_lsun) + ", " + kind + "}";
          };
          float t = float(s.temperature_K);
          if (ImGui::SliderFloat("temperature K", &t, 2500, 50000, "%.0f", ImGuiSliderFlags_Logarithmic))
            edit(key, star_entry("temperature_K = " + toml_number(t)));
          const char* classes[] = {"O5V", "B0V", "B5V", "A0V", "G2V", "M0V"};
          int which = -1;
          for (int c = 0; c < 6; ++c)
            if (s.spectral_class == classes[c]) which = c;
          if (ImGui::Combo("class", &which, classes, 6)) edit(key, star_entry(std::string("class = \"") + classes[which] + "\""));
          float p[3] = {s.position.x, s.position.y, s.position.z};
          if (ImGui::DragFloat3("position pc", p, 0.01f)) edit(key + ".position", toml_vec3(Vec3{p[0], p[1], p[2]}));
          ImGui::PopID();
        }
        ImGui::TextDisabled("Ctrl + drag in the view moves the first star");
      }
      if (ImGui::CollapsingHeader("Multiple scattering")) {
        int mode = int(scene.multiple_scattering);
        if (ImGui::Combo("between voxels", &mode, modes, 3)) {
          edit("render.multiple_scattering", std::string("\"") + modes[mode] + "\"");
          if (mode == 1 && scene.pyramid_levels == 0) edit("render.levels", "2");
          if (mode != 1) edit("render.levels", "0");
        }
        int levels = scene.pyramid_levels;
        if (mode == 1 && ImGui::SliderInt("pyramid levels", &levels, 1, 6)) edit("render.levels", std::to_string(levels));
      }
      if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
        int stretch = int(view.display.stretch);
        if (ImGui::Combo("stretch", &stretch, stretches, 3)) view.display.stretch = Stretch(stretch);
        ImGui::Checkbox("auto exposure", &view.display.auto_exposure);
        if (view.display.auto_exposure) {
          float pct = float(view.display.percentile);
          if (ImGui::SliderFloat("percentile", &pct, 50, 100, "%.2f")) view.display.percentile = pct;
          if (shown) ImGui::Text("exposure %.4g (auto)", shown_rgba.exposure);
        } else {
          float e = float(std::log10(view.camera.exposure));
          if (ImGui::SliderFloat("log10 exposure", &e, -8, 4)) view.camera.exposure = std::pow(10.0, e);
        }
        float white = float(view.display.white), soft = float(view.display.softening);
        if (ImGui::SliderFloat("white", &white, 0.01f, 100, "%.3g", ImGuiSliderFlags_Logarithmic)) view.display.white = white;
        if (view.display.stretch != Stretch::Linear &&
            ImGui::SliderFloat("softening", &soft, 1e-4f, 1, "%.4g", ImGuiSliderFlags_Logarithmic))
          view.display.softening = soft;
      }
      if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::InputText("image", screenshot_path, sizeof screenshot_path);
        if (ImGui::Button("screenshot (.png .exr .fits .h5)")) {
          try {
            if (!full) throw Error("no full-size frame yet: let the camera rest");
            write_screenshot(*full, view, screenshot_path, true);
            message = std::string("wrote ") + screenshot_path;
          } catch (const std::exception& e) {
            message = e.what();
          }
        }
        ImGui::InputText("scene", scene_path, sizeof scene_path);
        if (ImGui::Button("save scene (TOML)")) {
          try {
            const std::vector<std::string> written = save_scene(session, view.camera, view.display, view.keys, scene_path, true);
            message = "wrote";
            for (const std::string& f : written) message += " " + f;
            message += " (nebula render reproduces the view)";
          } catch (const std::exception& e) {
            message = e.what();
          }
        }
      }
      ImGui::End();
      if (scene.axial) {
        // The paint panel: a window of its own at the right, the map at its full width.
        ImGui::SetNextWindowPos(ImVec2(float(fb_w) - 430, 10), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(420, 0), ImGuiCond_FirstUseEver);
        ImGui::Begin("Axial map");
        // The map M(x, r) as an image (the axis at the bottom), painted with the mouse.
        std::shared_ptr<const AxialMap> map;
        try {
          map = session.axial_map();
        } catch (const std::exception& e) {
          ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", e.what());
        }
        std::vector<std::string> planes{"tau_v"};
        for (const std::string& b : scene.bands) planes.push_back("emission " + b);
        map_plane = std::min(map_plane, int(planes.size()) - 1);
        std::vector<const char*> plane_names;
        for (const std::string& p : planes) plane_names.push_back(p.c_str());
        ImGui::Combo("plane", &map_plane, plane_names.data(), int(plane_names.size()));
        BrushPlane plane;
        plane.band = map_plane - 1;
        if (map && (map != map_shown || map_plane != map_plane_shown)) {
          map_texture.upload(map_plane_image(*map, plane, &map_max));
          map_shown = map;
          map_plane_shown = map_plane;
        }
        if (map) {
          ImGui::Text("%d x %d texels of %.4g pc; largest %s %.4g%s", map->nx, map->nr, double(map->texel),
                      planes[size_t(map_plane)].c_str(), double(map_max), session.map_edited() ? "; edited" : "");
          const float w = ImGui::GetContentRegionAvail().x;
          const float h = w * float(map->nr) / float(map->nx);
          const ImVec2 at = ImGui::GetCursorScreenPos();
          map_at = at;
          map_size = ImVec2(w, h);
          ++map_frames;
          ImGui::Image((ImTextureID)(intptr_t)map_texture.id, ImVec2(w, h));
          // A button over the image takes the mouse (a plain image would let a drag move the window).
          ImGui::SetCursorScreenPos(at);
          ImGui::InvisibleButton("##map", ImVec2(w, h));
          const bool hovered = ImGui::IsItemHovered(), pressed = ImGui::IsItemActivated();
          const bool painting = ImGui::IsItemActive();
          const ImVec2 mouse = ImGui::GetMousePos();
          const BrushPoint here{(mouse.x - at.x) / w * float(map->nx), (1.0f - (mouse.y - at.y) / h) * float(map->nr)};
          if (hovered) {
            const float rp = brush_radius * w / float(map->nx);
            ImDrawList* draw = ImGui::GetWindowDrawList();
            if (brush_shape == 0)
              draw->AddCircle(mouse, rp, IM_COL32(255, 200, 0, 255), 32);
            else
              draw->AddRect(ImVec2(mouse.x - rp, mouse.y - rp), ImVec2(mouse.x + rp, mouse.y + rp), IM_COL32(255, 200, 0, 255));
          }
          const bool moved = painting && (here.x != last_dab.x || here.r != last_dab.r);
          if (painting && (pressed || moved)) {
            Stroke stroke;
            stroke.brush.shape = BrushShape(brush_shape);
            stroke.brush.mode = BrushMode(brush_mode);
            stroke.brush.soft = brush_soft;
            stroke.brush.radius = brush_radius;
            stroke.brush.value = brush_value;
            stroke.brush.plane = plane;
            stroke.dabs = pressed ? std::vector<BrushPoint>{here} : brush_segment(last_dab, here, brush_radius);
            try {
              session.paint(stroke);
            } catch (const std::exception& e) {
              message = e.what();
            }
            last_dab = here;
          }
        }
        const char* shapes[] = {"round", "square"};
        const char* brush_modes[] = {"set", "add", "erase"};
        ImGui::Combo("brush", &brush_shape, shapes, 2);
        ImGui::SameLine();
        ImGui::Checkbox("soft", &brush_soft);
        ImGui::Combo("mode", &brush_mode, brush_modes, 3);
        ImGui::SliderFloat("radius (texels)", &brush_radius, 0.5f, 128, "%.1f", ImGuiSliderFlags_Logarithmic);
        if (brush_mode != 2) {
          // Typed: emission values are small (0.02 per texel in the bipolar scene), tau_v ones near 1.
          ImGui::InputFloat(brush_mode == 1 ? "value to add (< 0 removes)" : "value", &brush_value, 0, 0, "%.4g");
          if (!std::isfinite(brush_value) || (brush_mode == 0 && brush_value < 0)) brush_value = 0;
        }
        ImGui::TextDisabled(map_plane == 0 ? "tau_v: V-band optical depth across one texel" : "emission: radiance gained across one texel");
        ImGui::InputText("map file", map_path, sizeof map_path);
        if (ImGui::Button("load map")) {
          try {
            session.load_map(map_path);
            message = std::string("loaded ") + map_path;
          } catch (const std::exception& e) {
            message = e.what();
          }
        }
        ImGui::SameLine();
        if (ImGui::Button("save map (HDF5)")) {
          try {
            session.save_map(map_path, true);
            message = std::string("wrote ") + map_path;
          } catch (const std::exception& e) {
            message = e.what();
          }
        }
        ImGui::SameLine();
        if (ImGui::Button("revert to the scene's")) session.revert_map();
        ImGui::End();
      }
    }
    if (last_frame_with_panels) last_frame_with_panels_drawn = true;
    ImGui::Render();
    glViewport(0, 0, fb_w, fb_h);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    if (automation && frames + 1 >= total_frames && (hide_panels || last_frame_with_panels_drawn)) {
      // The last automated frame: the full-size image alone, 1:1 in the window.
      if (!args.window_shot.empty() && !window_shot(window, args.window_shot))
        throw Error(args.window_shot + ": cannot write the window's pixels");
      glfwSwapBuffers(window);
      break;
    }
    glfwSwapBuffers(window);
    ++frames;
    if (automation && frames + 1 >= total_frames) {
      // Before the last frame: the full-size view, finished, with the panels hidden.
      session.request(requested);
      session.wait_idle();
      hide_panels = !args.show_panels;
      if (args.show_panels) {  // one more frame with the interface, then the shot
        std::optional<Frame> f = session.take_frame();
        if (f) {
          full = *f;
          shown_rgba = display_image(f->image, view.camera.exposure, view.display, f->metadata);
          texture.upload(shown_rgba);
          shown = std::move(f);
        }
        last_frame_with_panels = true;
      }
    }
  }

  session.wait_idle();
  const SessionStatus final_status = session.status();
  if (automation && !final_status.error.empty()) throw Error(final_status.error);
  if (automation && !args.screenshot.empty()) {
    if (std::optional<Frame> f = session.take_frame()) full = *f;
    if (!full) throw Error("--screenshot: no full-size frame was rendered");
    write_screenshot(*full, view, args.screenshot, args.force);
    std::printf("wrote %s\n", args.screenshot.c_str());
  }
  if (automation && !args.save_map.empty()) {
    session.save_map(args.save_map, args.force);
    std::printf("wrote %s\n", args.save_map.c_str());
  }
  if (automation && !args.save_scene.empty())
    for (const std::string& f : save_scene(session, view.camera, view.display, view.keys, args.save_scene, args.force))
      std::printf("wrote %s\n", f.c_str());
  if (automation) {
    std::printf("nebula-view: %d frames, bake %.3f s, last frame %.1f ms (%dx%d) on the %s\n", args.frames,
                final_status.bake_seconds, final_status.frame_seconds * 1e3, view.camera.width, view.camera.height,
                backend == Backend::Cuda ? "GPU" : "CPU");
    if (!args.window_shot.empty()) std::printf("wrote %s\n", args.window_shot.c_str());
  }
  if (pbo) glDeleteBuffers(1, &pbo);
  gpu.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return 0;
}

}  // namespace
}  // namespace nebula::viewer

int main(int argc, char** argv) {
  CLI::App app{"nebula-view: the interactive viewer of a scene (TOML) or the built-in demo"};
  nebula::viewer::Args a;
  app.add_option("SCENE", a.scene, "scene file (default: the built-in demo)");
  app.add_option("--backend", a.backend, "cpu, cuda or auto")->capture_default_str();
  app.add_option("--set", a.sets, "KEY=VALUE edit before the first frame (repeatable): any scene key, camera.* and display.*")
      ->allow_extra_args(false);
  app.add_option("--frames", a.frames, "automation: show N finished frames, then write the outputs and exit");
  app.add_option("--screenshot", a.screenshot, "automation: the last full-size frame to .png .exr .fits .h5");
  app.add_option("--window-shot", a.window_shot, "automation: the window's own pixels (PNG), the image 1:1");
  app.add_option("--save-scene", a.save_scene, "automation: the scene as shown, as TOML nebula render reproduces");
  app.add_option("--window-width", a.window_width, "window width")->capture_default_str();
  app.add_option("--window-height", a.window_height, "window height")->capture_default_str();
  app.add_option("--preview-scale", a.preview_scale, "while moving, render at 1/N of the size (default: 2 CPU, 1 GPU)");
  app.add_flag("--exact-preview", a.exact_preview,
               "march the moving camera's frames exactly too (default: each voxel's light taken once per view, "
               "about 4x faster on the CPU and 1.5x on the GPU; docs/marcher.md)");
  app.add_option("--preview-coarsening", a.preview_coarsening,
                 "while moving, render from the grid halved N times, baked on its own (default: 1 on the CPU, 0 on "
                 "the GPU)")
      ->check(CLI::Range(0, 16));
  app.add_option("--preview-photons", a.preview_photons,
                 "diffuse-field photons per band for the viewer's bakes, recorded in the scene (default: 65536 on "
                 "the CPU, the scene's on the GPU; 0: the scene's)");
  app.add_option("--paint", a.paints,
                 "x,r,radius,value[,plane]: a brush dab on an axial scene's map before the first frame (repeatable, "
                 "in order): texel coordinates along the axis and from it, radius in texels, the value, tau_v (the "
                 "default) or a band's emission")
      ->allow_extra_args(false);
  app.add_option("--paint-drag", a.paint_drag,
                 "automation with --show-panels: x0,r0,x1,r1,radius,value: a mouse drag on the Axial map panel's "
                 "image (texels), painted as the mouse paints, with the --brush-* options");
  app.add_option("--brush-shape", a.brush_shape, "--paint's brush: round or square")->capture_default_str();
  app.add_option("--brush-mode", a.brush_mode, "--paint's mode: set, add or erase (empties the texels)")->capture_default_str();
  app.add_flag("--brush-soft", a.brush_soft, "--paint's brush falls off as 1 - d / radius");
  app.add_option("--load-map", a.load_map, "an axial scene's map from HDF5 (tau_v, emission_<band>), before --paint");
  app.add_option("--save-map", a.save_map, "automation: the (painted) map to HDF5, as [axial] file reads it");
  app.add_flag("--force", a.force, "overwrite existing outputs");
  app.add_flag("--show-panels", a.show_panels, "automation: keep the interface in the window shot");
  app.add_option("--table-photons", a.table_photons, "photons per row for tables generated on first use (rows of tau_sct < 1 trace up to 32 times more; docs/tabulator.md)")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "nebula-view: error: %s (see --help)\n", e.what());
    return 2;
  }
  try {
    return nebula::viewer::run(a);
  } catch (const nebula::Error& e) {
    std::fprintf(stderr, "nebula-view: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nebula-view: internal error: %s\n", e.what());
    return 3;
  }
}
