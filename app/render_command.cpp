// `nebula render`: a scene (or the built-in demo) to an image, computing only
// what the scene reads.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/axial_render.h"
#include "app/commands.h"
#include "app/output_path.h"
#include "app/scene_setup.h"
#include "app/table_cache.h"
#include "core/error.h"
#include "core/progress.h"
#include "illumination/data_dir.h"
#include "illumination/extinction.h"
#include "illumination/optical_depth_bake.h"
#include "illumination/passband.h"
#include "illumination/star.h"
#include "imageio/image_output.h"
#include "multires/volume_pyramid.h"
#include "raycast/point_stars.h"
#include "raycast/pyramid_render.h"
#include "raycast/renderer.h"
#include "scene/scene_file.h"
#include "tables/table_file.h"

namespace nebula::app {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

struct Options {
  std::string scene_path, out, backend = "auto", table_photons = "3e4";
  std::vector<std::string> overrides;
  bool demo = false, force = false, quiet = false;
  int width = 0, height = 0, levels = -1;
  float smooth = 0;
};

void run_render(const Options& o) {
  const auto start = std::chrono::steady_clock::now();
  if (o.demo == !o.scene_path.empty()) throw Error("render: give a SCENE.toml or --demo (one of them)");
  if (o.demo && !o.overrides.empty())
    throw Error("--set: the demo takes no overrides; copy scenes/demo.toml and pass it instead");
  Scene scene = o.demo ? demo_scene() : load_scene(o.scene_path, o.overrides);
  if (scene.axial)
    return run_axial_render(scene, {o.out, o.backend, o.table_photons, o.force, o.quiet, o.width, o.height, o.smooth});
  if (o.width > 0) scene.camera.width = o.width;
  if (o.height > 0) scene.camera.height = o.height;
  if (o.width < 0 || o.height < 0) throw Error("--width/--height: must be positive");
  if (o.levels < -1) throw Error("--levels: must be 0 or more");
  if (o.levels >= 0) scene.pyramid_levels = o.levels;
  validate_scene(scene);
  const int most_levels = max_pyramid_levels(scene.density.shape);
  if (scene.pyramid_levels > most_levels)
    throw Error(std::string(o.levels >= 0 ? "--levels" : scene.path + ": render.levels") + ": " +
                std::to_string(scene.pyramid_levels) + " exceeds the " + std::to_string(most_levels) +
                " a grid of " + std::to_string(scene.density.shape.nx) + "x" + std::to_string(scene.density.shape.ny) +
                "x" + std::to_string(scene.density.shape.nz) + " allows (the coarsest level keeps 2 voxels)");
  const std::string out = o.out.empty() ? scene.output : o.out;
  check_output_path("-o", out, o.force);
  check_image_extension("-o", out);
  if (!(o.smooth == 0 || o.smooth >= 1e-3f)) throw Error("--smooth: step in voxels, at least 1e-3 (0: exact)");
  const Backend backend = parse_backend(o.backend);
  const uint64_t photons = parse_count("--table-photons", o.table_photons, 1000, double(kMaxPhotonsPerRow));
  const Camera camera = camera_of(scene.camera);
  const size_t n_bands = scene.bands.size();
  std::vector<std::string> computed;

  // Bands: the extinction law averaged over each passband, normalised to V;
  // star powers per band from black-body fractions.
  const SceneBands sb = scene_bands(scene);
  const std::vector<float>& ratios = sb.extinction_ratio;

  // Tables: one per distinct (albedo, g) among scattering bands, nothing for a = 0.
  std::map<std::pair<double, double>, std::shared_ptr<ScatteringTable>> tables;
  std::vector<const ScatteringTable*> band_table(n_bands, nullptr);
  for (size_t b = 0; b < n_bands; ++b) {
    const double a = scene.dust.albedo[b], g = scene.dust.g[b];
    if (a == 0) continue;
    const std::string file = b < scene.dust.table_files.size() ? scene.dust.table_files[b] : "";
    auto key = std::make_pair(a, g);
    if (!tables.count(key)) {
      if (!file.empty()) {
        auto t = std::make_shared<ScatteringTable>(read_table(file));
        if (std::fabs(t->albedo - a) > 1e-9 || std::fabs(t->g - g) > 1e-9)
          throw Error(file + ": albedo " + to_text(t->albedo) + ", g " + to_text(t->g) + " but band " + scene.bands[b] +
                      " of " + scene.path + " asks for albedo " + to_text(a) + ", g " + to_text(g));
        tables[key] = t;
        computed.push_back("table a=" + to_text(a) + " g=" + to_text(g) + ": read " + file);
      } else {
        TabulateParams p;
        p.albedo = a;
        p.g = g;
        p.binning = AngularBinning::UniformTheta;  // better for forward-peaked dust (docs/tabulator.md)
        p.photons_per_row = photons;
        std::string origin;
        tables[key] = std::make_shared<ScatteringTable>(cached_table(p, backend, o.quiet, &origin));
        computed.push_back("table a=" + to_text(a) + " g=" + to_text(g) + ": " + origin + " (" + table_cache_dir() + ")");
      }
    }
    band_table[b] = tables[key].get();
  }

  // Stars: one V-band depth bake each.
  const std::vector<std::vector<float>>& power = sb.star_power;
  std::vector<Vec3> positions;
  for (const SceneStar& star : scene.stars) positions.push_back(star.position);
  bool scatters = false;
  for (size_t b = 0; b < n_bands; ++b) scatters = scatters || band_table[b] != nullptr;
  BakeResult bake;
  if (scatters && !positions.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<Progress> progress;
    if (!o.quiet && backend == Backend::Cpu)
      progress = std::make_unique<Progress>("bake", uint64_t(positions.size()) * scene.density.shape.ny *
                                                        scene.density.shape.nz);
    bake = bake_star_depths(scene.density, positions, backend, progress.get());
    if (progress) progress->finish();
    computed.push_back("bake: " + std::to_string(positions.size()) + " star(s) x " +
                       std::to_string(scene.density.shape.count()) + " voxels, " + to_text(seconds_since(t0)) + " s");
  } else {
    computed.push_back("bake: skipped (no scattering band or no star)");
  }

  RenderInputs in;
  in.density = &scene.density;
  for (size_t b = 0; b < n_bands; ++b)
    in.bands.push_back(RenderBand{scene.bands[b], ratios[b], band_table[b] ? float(scene.dust.albedo[b]) : 0.0f,
                                  band_table[b], scene.emission.empty() ? nullptr : &scene.emission[b]});
  if (scatters)
    for (size_t k = 0; k < positions.size(); ++k) in.stars.push_back(RenderStar{positions[k], power[k], &bake.tau_v[k]});
  in.camera = camera;
  in.exposure = static_cast<float>(scene.camera.exposure);
  in.mode = MarchMode{o.smooth, true};
  RenderStats stats;
  std::unique_ptr<Progress> render_progress;
  if (!o.quiet && backend == Backend::Cpu)
    render_progress = std::make_unique<Progress>("render", uint64_t(camera.height));
  in.progress = render_progress.get();
  const PyramidResult pyramid = render_pyramid(in, scene.pyramid_levels, backend);
  if (render_progress) render_progress->finish();
  Image image = pyramid.image;
  for (const PyramidLevelReport& r : pyramid.report) {
    stats.seconds += r.render_seconds;
    stats.table_clamps += r.table_clamps;
  }
  if (scene.draw_stars) {
    std::vector<PointStar> points;
    for (size_t k = 0; k < positions.size(); ++k) points.push_back(PointStar{positions[k], power[k]});
    draw_point_stars(scene.density, points, ratios, camera, static_cast<float>(scene.camera.exposure),
                     scene.star_psf_pixels, image);
  }

  ImageMetadata meta = scene_metadata(scene, sb, camera);
  meta.entries.push_back({"mode", o.smooth > 0 ? "smooth step " + to_text(o.smooth) + " voxel" : "exact"});
  meta.entries.push_back({"pyramid_levels", std::to_string(scene.pyramid_levels)});
  write_image(image, out, meta, o.force);

  std::printf("rendered %s: %dx%d %s, %zu band(s), %zu star(s), grid %dx%dx%d, %s traversal, %s\n",
              scene.path.c_str(), camera.width, camera.height, to_string(scene.camera.kind), n_bands,
              scene.stars.size(), scene.density.shape.nx, scene.density.shape.ny, scene.density.shape.nz,
              o.smooth > 0 ? "smooth" : "exact", to_string(backend));
  std::printf("computed, and why:\n");
  for (size_t b = 0; b < n_bands; ++b)
    std::printf("  band %s: A/A_V %.4f (CCM89-family law, R_V %g, Bessell passband), albedo %g, g %g%s\n",
                scene.bands[b].c_str(), ratios[b], scene.dust.R_V, scene.dust.albedo[b], scene.dust.g[b],
                band_table[b] ? "" : " (no scattering: no table)");
  for (const std::string& c : computed) std::printf("  %s\n", c.c_str());
  std::printf("  emission: %s\n", scene.emission.empty() ? "none in the scene" : "per band grid");
  if (pyramid.report.size() == 1) std::printf("  pyramid levels: none\n");
  for (size_t j = 1; j < pyramid.report.size(); ++j) {
    const PyramidLevelReport& r = pyramid.report[j];
    std::printf("  pyramid level %d: grid %dx%dx%d (voxel %g pc), image %dx%d; build %.3f s, bake %.3f s, render %.3f s, "
                "%llu lookups beyond tau_max\n",
                r.level, r.shape.nx, r.shape.ny, r.shape.nz, r.shape.voxel, r.width, r.height, r.pyramid_seconds,
                r.bake_seconds, r.render_seconds, (unsigned long long)r.table_clamps);
  }
  std::printf("render: %.3f s marching, %llu table lookups beyond tau_max (clamped); total %.2f s\n", stats.seconds,
              (unsigned long long)stats.table_clamps, seconds_since(start));
  std::printf("wrote %s\n", out.c_str());
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "render a scene (TOML) or the built-in demo nebula to an image");
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene_path, "scene file (docs/scene.md)");
  cmd->add_flag("--demo", o->demo, "the built-in procedural nebula with an O-type star");
  cmd->add_option("-o,--output", o->out, "image: .exr .fits .png .h5 (default: the scene's output.file)");
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_option("--width", o->width, "image width (overrides the scene)");
  cmd->add_option("--height", o->height, "image height (overrides the scene)");
  cmd->add_option("--set", o->overrides, "KEY=VALUE scene override, e.g. camera.fov_deg=30 (repeatable)");
  cmd->add_option("--smooth", o->smooth, "smooth display mode: trilinear fields at this step in voxels (0: exact)")
      ->capture_default_str();
  cmd->add_option("--levels", o->levels,
                  "coarser pyramid levels for wide-range multiple scattering (default: the scene's render.levels, 0)");
  cmd->add_option("--table-photons", o->table_photons, "photons per row for tables generated on first use")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "overwrite an existing output");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress bars");
  cmd->callback([o] { run_render(*o); });
}

}  // namespace nebula::app
