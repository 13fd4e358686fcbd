// `nebula bench animate` and `nebula bench viewer` (issue 13): frames from one
// bake, and the viewer's frame and edit latency, on the demo's nebula at a
// chosen grid size. Medians after a warm-up, printed as Markdown rows for
// docs/performance.md, each with its baseline measured in the same run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/cli_support.h"
#include "core/error.h"
#include "core/frame_pool.h"
#include "core/gpu.h"
#include "pipeline/render_scene.h"
#include "scene/scene_file.h"
#include "viewer/gpu_frame.h"
#include "viewer/viewer_session.h"

namespace nebula::app {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

std::string device_name(Backend b) {
  if (b == Backend::Cpu) return "CPU (" + std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " threads)";
  std::string why;
  return gpu_available(&why) ? gpu_description() : "no GPU";
}

// The demo's nebula at n voxels per edge, its camera at width x height.
Scene bench_scene(int n, int width, int height, uint64_t diffuse_photons) {
  Scene s = demo_scene();
  ProceduralParams p = demo_procedural_params();
  p.n = n;
  s.density = procedural_nebula(p);
  s.camera.width = width;
  s.camera.height = height;
  s.diffuse.photons = diffuse_photons;
  return s;
}

// A camera on the demo's path at time t (0..10 s).
CameraSettings on_path(const Scene& s, double t) { return CameraPathSampler(*s.camera_path, s.camera).at(t); }

struct Common {
  std::string backends = "auto";
  int repeats = 5, size = 128, width = 1920, height = 1080;
  std::string diffuse_photons = "1048576";
};

void add_common(CLI::App* cmd, Common& c) {
  cmd->add_option("--backend", c.backends, "cpu, cuda, both or auto (= both when a GPU is present)")->capture_default_str();
  cmd->add_option("--repeats", c.repeats, "timed frames after the warm-up")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--size", c.size, "voxels per grid edge of the demo nebula")->capture_default_str()->check(CLI::Range(8, 1024));
  cmd->add_option("--width", c.width, "frame width")->capture_default_str()->check(CLI::Range(1, 65536));
  cmd->add_option("--height", c.height, "frame height")->capture_default_str()->check(CLI::Range(1, 65536));
  cmd->add_option("--diffuse-photons", c.diffuse_photons, "photons per band of the diffuse field")->capture_default_str();
}

void add_animate_bench(CLI::App* bench) {
  auto o = std::make_shared<Common>();
  CLI::App* cmd = bench->add_subcommand(
      "animate", "frames of a camera path from one bake (prepare_grid once, render_prepared per frame) against a "
                 "bake per frame; rendering only, no files");
  add_common(cmd, *o);
  cmd->callback([o] {
    const uint64_t photons = parse_count("--diffuse-photons", o->diffuse_photons, 1, 1e10);
    std::printf("| backend | device | grid | frame | bake s (once) | frame ms (median of %d) | frames/s | "
                "bake + frame s (baseline: a bake per frame) | speedup |\n|---|---|---|---|---|---|---|---|---|\n",
                o->repeats);
    for (Backend b : bench_backends(o->backends)) {
      const Scene scene = bench_scene(o->size, o->width, o->height, photons);
      RenderOptions options;
      options.backend = b;
      const auto t0 = Clock::now();
      const PreparedGrid prepared = prepare_grid(scene, options);
      const double bake = seconds_since(t0);
      render_prepared(prepared, on_path(scene, 0));  // warm-up
      std::vector<double> frames;
      for (int i = 0; i < o->repeats; ++i) {
        const CameraSettings camera = on_path(scene, 10.0 * (i + 1) / (o->repeats + 1));
        const auto t1 = Clock::now();
        RenderOutput frame = render_prepared(prepared, camera);
        frames.push_back(seconds_since(t1));
        recycle_frame_image(std::move(frame.image));  // as `nebula animate` does once a frame is written
      }
      // The baseline: what a frame cost when each render baked again (render_scene).
      Scene moved = scene;
      moved.camera = on_path(scene, 5.0);
      const auto t2 = Clock::now();
      render_scene(moved, options);
      const double baseline = seconds_since(t2);
      const double frame = median(frames);
      std::printf("| %s | %s | %d^3 | %dx%d | %.3f | %.2f | %.1f | %.3f | %.1fx |\n", to_string(b), device_name(b).c_str(),
                  o->size, o->width, o->height, bake, frame * 1e3, 1.0 / frame, baseline, baseline / frame);
      std::fflush(stdout);
    }
  });
}

// How far a preview is from the exact frame of the same view: the relative
// difference of the totals, and the 95th percentile of |preview / frame - 1|
// over pixels above 1e-3 of the frame's peak.
struct PreviewError {
  double total = 0, p95 = 0;
};
PreviewError preview_error(const Image& exact, const Image& preview) {
  PreviewError e;
  if (exact.pixels.size() != preview.pixels.size()) return e;
  double sum_exact = 0, sum_preview = 0, peak = 0;
  for (size_t i = 0; i < exact.pixels.size(); ++i) {
    sum_exact += exact.pixels[i];
    sum_preview += preview.pixels[i];
    peak = std::max(peak, double(exact.pixels[i]));
  }
  std::vector<double> rel;
  for (size_t i = 0; i < exact.pixels.size(); ++i)
    if (exact.pixels[i] > 1e-3 * peak) rel.push_back(std::fabs(preview.pixels[i] / double(exact.pixels[i]) - 1.0));
  e.total = sum_exact > 0 ? sum_preview / sum_exact - 1.0 : 0.0;
  if (!rel.empty()) {
    const size_t k = size_t(0.95 * double(rel.size() - 1));
    std::nth_element(rel.begin(), rel.begin() + long(k), rel.end());
    e.p95 = rel[k];
  }
  return e;
}

void add_viewer_bench(CLI::App* bench) {
  auto o = std::make_shared<Common>();
  o->width = 1280;
  o->height = 720;
  auto coarsening = std::make_shared<int>(-1);
  CLI::App* cmd = bench->add_subcommand(
      "viewer", "the viewer's session without a window: a new view to its frame, and a slider edit (albedo) to the "
                "re-baked frame; the hand-over to OpenGL is not included");
  add_common(cmd, *o);
  cmd->add_option("--preview-coarsening", *coarsening,
                 "the preview's grid halved N times, as nebula-view's option (default: 1 on the CPU, 0 on the GPU)")
      ->check(CLI::Range(0, 16));
  cmd->callback([o, coarsening] {
    const uint64_t photons = parse_count("--diffuse-photons", o->diffuse_photons, 1, 1e10);
    std::printf("| backend | device | grid | frame | view to frame ms (median of %d) | frames/s | edit to frame ms "
                "(median of %d) | first bake s |\n|---|---|---|---|---|---|---|---|\n",
                o->repeats, o->repeats);
    for (Backend b : bench_backends(o->backends)) {
      viewer::SceneSource source = viewer::SceneSource::demo();
      source.set("density.procedural.n", std::to_string(o->size));
      source.set("camera.width", std::to_string(o->width));
      source.set("camera.height", std::to_string(o->height));
      source.set("render.diffuse_photons", std::to_string(photons));
      viewer::ViewerOptions options;
      options.backend = b;
      options.preview_coarsening = *coarsening >= 0 ? *coarsening : (b == Backend::Cpu ? 1 : 0);  // as nebula-view
      const auto t0 = Clock::now();
      viewer::Session session(source, options);
      const Scene& scene = session.scene();
      const CameraSettings home = scene.camera;
      session.request(home);
      session.wait_idle();
      const double first = seconds_since(t0);
      session.take_frame();
      std::vector<double> views, previews, edits, preview_total, preview_p95;
      for (int i = 0; i < o->repeats; ++i) {
        CameraSettings c = on_path(scene, 10.0 * (i + 1) / (o->repeats + 1));
        c.width = o->width;
        c.height = o->height;
        const auto t1 = Clock::now();
        session.request(c);
        session.wait_idle();
        views.push_back(seconds_since(t1));
        const std::optional<viewer::Frame> exact = session.take_frame();
        // The moving camera's preview of the same view (MarchMode::voxel_sources), and how far it is from the frame.
        const auto t2 = Clock::now();
        session.request(c, true);
        session.wait_idle();
        previews.push_back(seconds_since(t2));
        const std::optional<viewer::Frame> quick = session.take_frame();
        if (exact && quick) {
          const PreviewError e = preview_error(exact->image, quick->image);
          preview_total.push_back(e.total);
          preview_p95.push_back(e.p95);
        }
      }
      for (int i = 0; i < o->repeats; ++i) {
        const auto t1 = Clock::now();
        session.edit("dust.albedo", i % 2 == 0 ? "0.65" : "0.6");
        session.wait_idle();
        edits.push_back(seconds_since(t1));
        session.take_frame();
      }
      if (!session.status().error.empty()) throw Error("bench viewer: " + session.status().error);
      {
        // Where the last edit's time went (its report): the bake's parts, then the frame.
        const viewer::SessionStatus st = session.status();
        double tables = 0;
        for (const TableReport& t : st.report.tables) tables += t.seconds;
        std::printf("| %s edit, the last: bake %.1f ms (scene load and prepare_grid) = star depths %.1f ms%s + "
                    "tables %.1f ms + diffuse field %.1f ms (photon passes %.1f ms) + rest; frame %.1f ms |\n",
                    to_string(b), st.bake_seconds * 1e3, st.report.bake.seconds * 1e3,
                    st.report.bake.reused ? " (reused)" : "", tables * 1e3, st.report.diffuse.wall_seconds * 1e3,
                    st.report.diffuse.seconds * 1e3, st.frame_seconds * 1e3);
      }
      std::printf("| %s | %s | %d^3 | %dx%d | %.2f | %.1f | %.1f | %.3f |\n", to_string(b), device_name(b).c_str(),
                  o->size, o->width, o->height, median(views) * 1e3, 1.0 / median(views), median(edits) * 1e3, first);
      std::printf("| %s preview (moving camera: voxel sources) | %s | %d^3 | %dx%d | %.2f | %.1f | total %+.2f%%, 95th "
                  "percentile pixel %.2f%% from the frame (medians over the views) | |\n",
                  to_string(b), device_name(b).c_str(), o->size, o->width, o->height, median(previews) * 1e3,
                  1.0 / median(previews), preview_total.empty() ? 0.0 : 100 * median(preview_total),
                  preview_p95.empty() ? 0.0 : 100 * median(preview_p95));
      // The window's GPU frame: render and tone map into device memory (the OpenGL pixel buffer's
      // stand-in: mapping a registered buffer needs a window, which a benchmark machine lacks).
      if (b == Backend::Cuda && viewer::GpuFrame::available()) {
        std::shared_ptr<const PreparedGrid> prepared = session.prepared();
        if (prepared) {
          // The exact frame (a resting camera's) and the preview (a moving camera's, nebula-view's
          // default), alternated view by view.
          viewer::GpuFrame gpu;
          std::vector<double> gpu_ms, preview_ms;
          for (int i = 0; i <= o->repeats; ++i) {
            CameraSettings c = on_path(scene, 10.0 * (i + 1) / (o->repeats + 2));
            c.width = o->width;
            c.height = o->height;
            RenderInputs in = prepared->inputs;
            in.camera = make_camera(c);
            in.exposure = 1.0f;
            for (bool preview : {false, true}) {
              in.mode.voxel_sources = preview;
              const double seconds = gpu.render_to_device(in, 0.02, scene.display);
              if (i > 0) (preview ? preview_ms : gpu_ms).push_back(seconds * 1e3);  // the first is the warm-up
            }
          }
          std::printf("| cuda GPU frame (render + tone map on the device, no host copy) | %s | %d^3 | %dx%d | %.2f | "
                      "%.1f | | |\n", device_name(b).c_str(), o->size, o->width, o->height, median(gpu_ms),
                      1e3 / median(gpu_ms));
          std::printf("| cuda GPU frame, moving camera (voxel sources, as nebula-view) | %s | %d^3 | %dx%d | %.2f | "
                      "%.1f | | |\n", device_name(b).c_str(), o->size, o->width, o->height, median(preview_ms),
                      1e3 / median(preview_ms));
        }
      }
      std::fflush(stdout);
    }
  });
}

}  // namespace

void add_frame_benchmarks(CLI::App* bench) {
  add_animate_bench(bench);
  add_viewer_bench(bench);
}

}  // namespace nebula::app
