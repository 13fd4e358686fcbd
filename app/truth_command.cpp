// `nebula truth`: the ground-truth path tracer (validation/path_tracer.h) on
// exactly the scene `nebula render` sees: the same density, per-band
// extinction ratios, albedo and g, star band powers, emission and camera
// (app/scene_setup.h). Writes the image and, beside it, the variance of every
// pixel's mean (OUT with ".var" before the extension), which `nebula compare`
// finds.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/output_path.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "core/progress.h"
#include "imageio/image_output.h"
#include "raycast/point_stars.h"
#include "scene/scene_file.h"
#include "validation/image_compare.h"
#include "validation/truth_renderer.h"

namespace nebula::app {
namespace {

struct Options {
  std::string scene_path, out, backend = "auto", spp;
  std::vector<std::string> overrides;
  bool demo = false, force = false, quiet = false, equiangular = false;
  std::string transmittance = "ratio";
  int width = 0, height = 0, max_orders = 0, majorant_block = 4;
  uint64_t seed = 1;
};

void run_truth(const Options& o) {
  const auto start = std::chrono::steady_clock::now();
  if (o.demo == !o.scene_path.empty()) throw Error("truth: give a SCENE.toml or --demo (one of them)");
  if (o.demo && !o.overrides.empty()) throw Error("--set: the demo takes no overrides; copy scenes/demo.toml");
  if (o.out.empty()) throw Error("truth: -o OUT is required (the variance goes beside it)");
  const int spp = static_cast<int>(parse_count("--spp", o.spp, 2, 1e7));
  if (o.max_orders < 0) throw Error("--max-orders: must be 0 (all orders) or positive");
  if (o.majorant_block < 1 || o.majorant_block > 256) throw Error("--majorant-block: must be 1 to 256 voxels");
  if (o.width < 0 || o.height < 0) throw Error("--width/--height: must be positive");
  if (o.transmittance != "ratio" && o.transmittance != "exact")
    throw Error("--transmittance: expected ratio or exact, got '" + o.transmittance + "'");
  Scene scene = o.demo ? demo_scene() : load_scene(o.scene_path, o.overrides);
  if (o.width > 0) scene.camera.width = o.width;
  if (o.height > 0) scene.camera.height = o.height;
  validate_scene(scene);
  const std::string var_out = variance_path(o.out);
  check_image_extension("-o", o.out);
  check_output_path("-o", o.out, o.force);
  check_output_path("-o (variance)", var_out, o.force);
  const Backend backend = parse_backend(o.backend);
  const Camera camera = camera_of(scene.camera);
  const SceneBands sb = scene_bands(scene);
  const size_t n_bands = scene.bands.size();

  TruthInputs in;
  in.density = &scene.density;
  for (size_t b = 0; b < n_bands; ++b)
    in.bands.push_back(TruthBand{scene.bands[b], sb.extinction_ratio[b], float(scene.dust.albedo[b]),
                                 float(scene.dust.g[b]), scene.emission.empty() ? nullptr : &scene.emission[b]});
  for (size_t k = 0; k < scene.stars.size(); ++k) in.stars.push_back(TruthStar{scene.stars[k].position, sb.star_power[k]});
  in.camera = camera;
  in.exposure = static_cast<float>(scene.camera.exposure);
  in.spp = spp;
  in.seed = o.seed;
  in.max_orders = o.max_orders;
  in.majorant_block = o.majorant_block;
  in.exact_transmittance = o.transmittance == "exact";
  in.equiangular = o.equiangular;
  std::unique_ptr<Progress> progress;
  if (!o.quiet && backend == Backend::Cpu) progress = std::make_unique<Progress>("truth", uint64_t(camera.height));
  in.progress = progress.get();
  TruthOutput result = render_truth(in, backend);
  if (progress) progress->finish();
  if (scene.draw_stars) {
    // Stars seen directly: the same deterministic drawing as `nebula render`
    // (exact transmittance, a Gaussian PSF); no variance.
    std::vector<PointStar> points;
    for (size_t k = 0; k < scene.stars.size(); ++k) points.push_back(PointStar{scene.stars[k].position, sb.star_power[k]});
    draw_point_stars(scene.density, points, sb.extinction_ratio, camera, static_cast<float>(scene.camera.exposure),
                     scene.star_psf_pixels, result.image);
  }

  ImageMetadata meta = scene_metadata(scene, sb, camera);
  meta.entries.push_back({"mode", "truth spp " + std::to_string(spp) + " seed " + std::to_string(o.seed) + " " +
                                      o.transmittance + " transmittance" + (o.equiangular ? " equiangular" : "") +
                                      (o.max_orders ? " orders<=" + std::to_string(o.max_orders) : "")});
  ImageMetadata var_meta = meta;
  var_meta.units = "(L_sun pc^-2 sr^-1 x exposure)^2, variance of the pixel mean";
  write_image(result.variance, var_out, var_meta, o.force);
  write_image(result.image, o.out, meta, o.force);

  const double s = result.seconds;
  std::printf("truth %s: %dx%d %s, %zu band(s), %zu star(s), grid %dx%dx%d, %d spp, %s\n", scene.path.c_str(),
              camera.width, camera.height, to_string(scene.camera.kind), n_bands, scene.stars.size(),
              scene.density.shape.nx, scene.density.shape.ny, scene.density.shape.nz, spp, to_string(backend));
  std::printf("  paths %llu, collisions (path vertices) %llu, tentative collisions %llu, capped %llu\n",
              (unsigned long long)result.paths, (unsigned long long)result.counters.vertices,
              (unsigned long long)result.counters.tentative, (unsigned long long)result.counters.capped);
  std::printf("  tracing %.3f s: %.3g vertices/s, %.3g paths/s, %.3g spp/s at this size; total %.2f s\n", s,
              result.counters.vertices / s, result.paths / s, spp / s,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::printf("wrote %s and %s\n", o.out.c_str(), var_out.c_str());
}

}  // namespace

void add_truth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("truth", "ground truth: unbiased volumetric path tracing of a scene, with variance");
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene_path, "scene file (docs/scene.md)");
  cmd->add_flag("--demo", o->demo, "the built-in procedural nebula");
  cmd->add_option("--spp", o->spp, "samples per pixel and band (>= 2)")->required();
  cmd->add_option("-o,--output", o->out, "image .h5 .fits .exr (variance beside it as OUT.var.EXT)")->required();
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_option("--width", o->width, "image width (overrides the scene)");
  cmd->add_option("--height", o->height, "image height (overrides the scene)");
  cmd->add_option("--set", o->overrides, "KEY=VALUE scene override (repeatable)");
  cmd->add_option("--seed", o->seed, "Philox key")->capture_default_str();
  cmd->add_option("--max-orders", o->max_orders, "scattering orders kept (0: all, the truth)")->capture_default_str();
  cmd->add_option("--majorant-block", o->majorant_block, "voxels per majorant-grid block edge")->capture_default_str();
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
