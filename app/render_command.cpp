// `nebula render`: a scene (or the built-in demo) to an image through the
// render pipeline (pipeline/render_scene.h), printing what it computed and why.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/print_report.h"
#include "core/error.h"
#include "montecarlo/tabulate.h"
#include "pipeline/render_scene.h"

namespace nebula::app {
namespace {

struct Options {
  SceneOptions scene;
  std::string out, backend = "auto", table_photons = "3e4";
  bool force = false, quiet = false;
  int levels = -1;
  float smooth = 0;
};

void run_render(const Options& o) {
  if (o.levels < -1) throw Error("--levels: must be 0 or more");
  Scene scene = load_scene_options("render", o.scene);
  if (o.levels >= 0) scene.pyramid_levels = o.levels;
  if (o.levels > 0) scene.multiple_scattering = MultipleScattering::Pyramid;  // levels are the pyramid's
  const std::string out = o.out.empty() ? scene.output : o.out;
  check_image_output("-o", out, o.force);
  check_not_an_input("-o", out, scene.inputs);
  check_run_memory(scene, RunKind::Fast);
  RenderOptions options;
  options.backend = parse_backend(o.backend);
  options.table_photons = parse_count("--table-photons", o.table_photons, 1000, double(kMaxBasePhotons));
  options.smooth_step = o.smooth;
  options.progress = !o.quiet;
  OptionNames names{{"smooth_step", "--smooth"}, {"backend", "--backend"}};
  if (o.levels >= 0) names["render.levels"] = "--levels";
  naming_options(names, [&] {
    const RenderOutput result = render_scene(scene, options);
    write_image(result.image, out, result.metadata, o.force);
    print_report(result.report);
  }, scene.path);
  std::printf("wrote %s\n", out.c_str());
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "render a scene (TOML) or the built-in demo nebula to an image");
  auto o = std::make_shared<Options>();
  add_scene_options(cmd, o->scene);
  cmd->add_option("-o,--output", o->out, "image: .exr .fits .png .h5 (default: the scene's output.file)");
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_option("--smooth", o->smooth, "smooth display mode: trilinear fields at this step in voxels (0: exact)")
      ->capture_default_str();
  cmd->add_option("--levels", o->levels,
                  "multiple scattering by the 2005 paper's resolution pyramid with this many coarser levels, instead "
                  "of the diffuse field (default: the scene's render.levels, 0)");
  cmd->add_option("--table-photons", o->table_photons, "photons per row for tables generated on first use (rows of tau_sct < 1 trace up to 32 times more; docs/tabulator.md)")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "overwrite an existing output");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress bars");
  cmd->callback([o] { run_render(*o); });
}

}  // namespace nebula::app
