// `nebula truth`: the ground-truth path tracer on exactly the scene `nebula
// render` sees (pipeline/render_scene.h). Writes the image and, beside it,
// the variance of every pixel's mean (OUT with ".var" before the extension),
// which `nebula compare` finds.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/print_report.h"
#include "core/error.h"
#include "pipeline/render_scene.h"
#include "imageio/image_output.h"

namespace nebula::app {
namespace {

struct Options {
  SceneOptions scene;
  std::string out, backend = "auto", spp;
  bool force = false, quiet = false, equiangular = false;
  std::string transmittance = "ratio";
  int max_orders = 0, majorant_block = 4, axial_voxels = 256;
  uint64_t seed = 1;
};

void run_truth(const Options& o) {
  if (o.out.empty()) throw Error("truth: -o OUT is required (the variance goes beside it)");
  if (o.transmittance != "ratio" && o.transmittance != "exact")
    throw Error("--transmittance: expected ratio or exact, got '" + o.transmittance + "'");
  TruthOptions options;
  options.spp = static_cast<int>(parse_count("--spp", o.spp, 2, 1e7));
  options.seed = o.seed;
  options.max_orders = o.max_orders;
  options.majorant_block = o.majorant_block;
  options.axial_voxels = o.axial_voxels;
  options.exact_transmittance = o.transmittance == "exact";
  options.equiangular = o.equiangular;
  options.progress = !o.quiet;
  const OptionNames names{{"spp", "--spp"}, {"max_orders", "--max-orders"}, {"majorant_block", "--majorant-block"},
                          {"axial_voxels", "--axial-voxels"},
                          {"backend", "--backend"}};
  const Scene scene = load_scene_options("truth", o.scene);
  const std::string var_out = variance_path(o.out);
  check_image_output("-o", o.out, o.force);
  check_output_path("-o (variance)", var_out, o.force);
  check_not_an_input("-o", o.out, scene.inputs);
  check_not_an_input("-o (variance)", var_out, scene.inputs);
  options.backend = parse_backend(o.backend);
  naming_options(names, [&] {
    const TruthRenderOutput result = truth_scene(scene, options);
    write_image(result.variance, var_out, result.variance_metadata, o.force);
    write_image(result.image, o.out, result.metadata, o.force);
    print_report(result.report);
  }, scene.path);
  std::printf("wrote %s and %s\n", o.out.c_str(), var_out.c_str());
}

}  // namespace

void add_truth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("truth", "ground truth: unbiased volumetric path tracing of a scene, with variance");
  auto o = std::make_shared<Options>();
  add_scene_options(cmd, o->scene);
  cmd->add_option("--spp", o->spp, "samples per pixel and band (>= 2)")->required();
  cmd->add_option("-o,--output", o->out, "image .h5 .fits .exr (variance beside it as OUT.var.EXT)")->required();
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Philox key")->capture_default_str();
  cmd->add_option("--max-orders", o->max_orders, "scattering orders kept (0: all, the truth)")->capture_default_str();
  cmd->add_option("--majorant-block", o->majorant_block, "voxels per majorant-grid block edge")->capture_default_str();
  cmd->add_option("--axial-voxels", o->axial_voxels,
                  "an axial map is traced voxelized in its own frame: voxels along its longer side")
      ->capture_default_str();
  cmd->add_option("--transmittance", o->transmittance,
                  "to the stars: ratio (residual ratio tracking) or exact (the voxel sum: no noise)")
      ->capture_default_str();
  cmd->add_flag("--equiangular", o->equiangular,
               "next-event estimation also from equiangular samples towards each star, combined by MIS "
               "(bounded weights for stars inside dust)");
  cmd->add_flag("--force", o->force, "overwrite existing outputs");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress bar");
  cmd->callback([o] { run_truth(*o); });
}

}  // namespace nebula::app
