// `nebula animate`: a scene's camera path ([animation] keyframes) to numbered
// frames with one bake, and an MP4 through ffmpeg (animation/animate.h).
#include <cstdio>
#include <memory>
#include <string>

#include "animation/animate.h"
#include "app/cli_support.h"
#include "app/commands.h"
#include "app/print_report.h"
#include "core/error.h"
#include "montecarlo/tabulate.h"

namespace nebula::app {
namespace {

struct Options {
  SceneOptions scene;
  std::string out, video, backend = "auto", table_photons = "3e4";
  double fps = 30, duration = 0, from = 0, to = 0;
  CLI::Option *duration_given = nullptr, *from_given = nullptr, *to_given = nullptr;
  bool force = false, resume = false, quiet = false;
  float smooth = 0;
};

void run_animate(const Options& o) {
  if (o.out.empty()) throw Error("animate: -o PATTERN is required (e.g. -o frames/frame_%04d.png)");
  Scene scene = load_scene_options("animate", o.scene);
  AnimateOptions a;
  a.pattern = o.out;
  a.fps = o.fps;
  if (o.duration_given->count() > 0) a.duration = o.duration;
  if (o.from_given->count() > 0) a.from = o.from;
  if (o.to_given->count() > 0) a.to = o.to;
  a.force = o.force;
  a.resume = o.resume;
  a.existing_hint = ": --resume finishes that run, --force renders every frame again";
  a.video = o.video;
  a.render.backend = parse_backend(o.backend);
  a.render.table_photons = parse_count("--table-photons", o.table_photons, 1000, double(kMaxBasePhotons));
  a.render.smooth_step = o.smooth;
  a.render.progress = !o.quiet;
  a.progress = !o.quiet;
  a.quiet = o.quiet;
  OptionNames names{{"pattern", "-o"},          {"fps", "--fps"},       {"duration", "--duration"},
                    {"from", "--from"},         {"to", "--to"},         {"video", "--video"},
                    {"resume", "--resume"},     {"smooth_step", "--smooth"}, {"backend", "--backend"}};
  AnimateResult result;
  naming_options(names, [&] {
    // Outputs never overwrite inputs (the first frame stands for all: the rest differ only in their number).
    check_not_an_input("-o", parse_frame_pattern(o.out).path(0), scene.inputs);
    if (!o.video.empty()) check_not_an_input("--video", o.video, scene.inputs);
    result = animate(scene, a);
  }, scene.path);
  if (result.rendered > 0) print_report(result.report);
  const double frames = double(result.rendered);
  std::printf("animate: %lld frames (%lld to %lld at %g fps), %lld rendered, %lld kept from an earlier run\n",
              result.plan.count(), result.plan.first, result.plan.last, result.plan.fps, result.rendered,
              result.skipped);
  std::printf("  one bake for all frames: %.3g s; rendering %.3g s (%.3g s a frame, %.3g frames/s); writing %.3g s\n",
              result.prepare_seconds, result.render_seconds, frames > 0 ? result.render_seconds / frames : 0.0,
              result.render_seconds > 0 ? frames / result.render_seconds : 0.0, result.write_seconds);
  std::printf("wrote %s (frames %s to %s)\n", parse_frame_pattern(o.out).folder().c_str(),
              parse_frame_pattern(o.out).path(result.plan.first).c_str(),
              parse_frame_pattern(o.out).path(result.plan.last).c_str());
  if (!result.video.empty()) std::printf("wrote %s (H.264)\n", result.video.c_str());
}

}  // namespace

void add_animate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "animate", "render a scene's camera path ([animation] keyframes) to numbered frames with one bake, and an MP4");
  auto o = std::make_shared<Options>();
  add_scene_options(cmd, o->scene);
  cmd->add_option("-o,--output", o->out, "frame pattern with the frame number as %d or %04d: frames/frame_%04d.png "
                                         "(.png .exr .fits .h5)");
  cmd->add_option("--fps", o->fps, "frames per second")->capture_default_str();
  o->duration_given = cmd->add_option("--duration", o->duration,
                                      "seconds the path lasts (the keyframe times scaled; default: as written)");
  o->from_given = cmd->add_option("--from", o->from, "render from this time on (s, on the path)");
  o->to_given = cmd->add_option("--to", o->to, "render up to this time (s, on the path)");
  cmd->add_option("--video", o->video, "also encode the PNG frames as an H.264 MP4 (needs ffmpeg)");
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_option("--smooth", o->smooth, "smooth display mode: trilinear fields at this step in voxels (0: exact)")
      ->capture_default_str();
  cmd->add_option("--table-photons", o->table_photons, "photons per row for tables generated on first use (rows of tau_sct < 1 trace up to 32 times more; docs/tabulator.md)")
      ->capture_default_str();
  cmd->add_flag("--resume", o->resume, "keep the frames an interrupted run of the same path finished");
  cmd->add_flag("--force", o->force, "render every frame again over existing ones (and overwrite the video)");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress bars");
  cmd->callback([o] { run_animate(*o); });
}

}  // namespace nebula::app
