#include "app/axial_render.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "app/output_path.h"
#include "app/scene_setup.h"
#include "app/table_cache.h"
#include "core/error.h"
#include "core/progress.h"
#include "illumination/axial_bake.h"
#include "imageio/image_output.h"
#include "raycast/axial_renderer.h"
#include "scene/density_sources.h"
#include "tables/table_file.h"

namespace nebula::app {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

void run_axial_render(Scene& scene, const AxialCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  if (o.smooth != 0) throw Error("--smooth: not for axial maps (their step is axial.step_texels)");
  if (o.width > 0) scene.camera.width = o.width;
  if (o.height > 0) scene.camera.height = o.height;
  if (o.width < 0 || o.height < 0) throw Error("--width/--height: must be positive");
  validate_scene(scene);
  const std::string out = o.out.empty() ? scene.output : o.out;
  check_output_path("-o", out, o.force);
  check_image_extension("-o", out);
  const Backend backend = parse_backend(o.backend);
  const uint64_t photons = parse_count("--table-photons", o.table_photons, 1000, double(kMaxPhotonsPerRow));
  const AxialSpec& spec = *scene.axial;
  const AxialSkip skip = parse_axial_skip(spec.skip, scene.path + ": axial.skip");
  const Camera camera = camera_of(scene.camera);
  const size_t n_bands = scene.bands.size();
  std::vector<std::string> computed;

  const auto t_map = std::chrono::steady_clock::now();
  const AxialMap map = build_axial_map(scene);
  computed.push_back("map: " + spec.source + " " + (spec.source == "synthetic" ? spec.synthetic : spec.path) + ", " +
                     std::to_string(map.nx) + " x " + std::to_string(map.nr) + " texels of " + to_text(map.texel) +
                     " pc, " + std::to_string(map.emission.size()) + " emission plane(s), height-map max " +
                     std::to_string(map.global_max) + ", " + to_text(seconds_since(t_map)) + " s");
  const SceneBands sb = scene_bands(scene);

  // Tables: one per distinct (albedo, g) among scattering bands, as for grids.
  std::map<std::pair<double, double>, std::shared_ptr<ScatteringTable>> tables;
  std::vector<const ScatteringTable*> band_table(n_bands, nullptr);
  if (!scene.stars.empty())
    for (size_t b = 0; b < n_bands; ++b) {
      const double a = scene.dust.albedo[b], g = scene.dust.g[b];
      if (a == 0) continue;
      const std::string file = b < scene.dust.table_files.size() ? scene.dust.table_files[b] : "";
      const auto key = std::make_pair(a, g);
      if (!tables.count(key)) {
        if (!file.empty()) {
          auto t = std::make_shared<ScatteringTable>(read_table(file));
          if (std::fabs(t->albedo - a) > 1e-9 || std::fabs(t->g - g) > 1e-9)
            throw Error(file + ": albedo " + to_text(t->albedo) + ", g " + to_text(t->g) + " but band " +
                        scene.bands[b] + " of " + scene.path + " asks for albedo " + to_text(a) + ", g " + to_text(g));
          tables[key] = t;
          computed.push_back("table a=" + to_text(a) + " g=" + to_text(g) + ": read " + file);
        } else {
          TabulateParams p;
          p.albedo = a;
          p.g = g;
          p.binning = AngularBinning::UniformTheta;
          p.photons_per_row = photons;
          std::string origin;
          tables[key] = std::make_shared<ScatteringTable>(cached_table(p, backend, o.quiet, &origin));
          computed.push_back("table a=" + to_text(a) + " g=" + to_text(g) + ": " + origin + " (" + table_cache_dir() + ")");
        }
      }
      band_table[b] = tables[key].get();
    }
  bool scatters = false;
  for (const ScatteringTable* t : band_table) scatters = scatters || t != nullptr;

  // Stars on the axis: one 2D bake each.
  std::vector<float> star_x;
  for (const SceneStar& s : scene.stars) star_x.push_back(dot(s.position - map.origin, map.axis));
  BakeResult bake;
  if (scatters) {
    const auto t0 = std::chrono::steady_clock::now();
    bake = bake_axial_star_depths(map.nx, map.nr, map.texel, map.tau_v, star_x, backend);
    computed.push_back("bake: " + std::to_string(star_x.size()) + " star(s) on the axis x " +
                       std::to_string(map.count()) + " texels, " + to_text(seconds_since(t0)) + " s");
  } else {
    computed.push_back("bake: skipped (no scattering band or no star)");
  }

  AxialRenderInputs in;
  in.map = &map;
  for (size_t b = 0; b < n_bands; ++b)
    in.bands.push_back(AxialRenderBand{scene.bands[b], sb.extinction_ratio[b],
                                       band_table[b] ? float(scene.dust.albedo[b]) : 0.0f, band_table[b]});
  if (scatters)
    for (size_t k = 0; k < star_x.size(); ++k)
      in.stars.push_back(AxialRenderStar{scene.stars[k].position, sb.star_power[k], &bake.tau_v[k]});
  in.camera = camera;
  in.exposure = static_cast<float>(scene.camera.exposure);
  in.step = static_cast<float>(spec.step_texels * map.texel);
  in.skip = skip;
  AxialRenderStats stats;
  std::unique_ptr<Progress> progress;
  if (!o.quiet && backend == Backend::Cpu) progress = std::make_unique<Progress>("render", uint64_t(camera.height));
  in.progress = progress.get();
  Image image = render_axial(in, backend, &stats);
  if (progress) progress->finish();
  for (float& v : image.pixels)
    if (!std::isfinite(v)) throw Error("axial render: a non-finite pixel (a bug: please report the scene)");

  ImageMetadata meta = scene_metadata(scene, sb, camera);
  meta.entries.push_back({"mode", std::string("axial ") + to_string(skip) + " step " + to_text(spec.step_texels) + " texel"});
  write_image(image, out, meta, o.force);

  std::printf("rendered %s: %dx%d %s, %zu band(s), %zu star(s), axial map %dx%d, skip %s%s, step %g texel, %s\n",
              scene.path.c_str(), camera.width, camera.height, to_string(scene.camera.kind), n_bands,
              scene.stars.size(), map.nx, map.nr, to_string(skip),
              stats.skip_used != skip ? " (ran naive: the map has no empty texel)" : "", spec.step_texels,
              to_string(backend));
  std::printf("computed, and why:\n");
  for (size_t b = 0; b < n_bands; ++b)
    std::printf("  band %s: A/A_V %.4f (CCM89-family law, R_V %g, Bessell passband), albedo %g, g %g%s\n",
                scene.bands[b].c_str(), sb.extinction_ratio[b], scene.dust.R_V, scene.dust.albedo[b], scene.dust.g[b],
                band_table[b] ? "" : " (no scattering: no table)");
  for (const std::string& c : computed) std::printf("  %s\n", c.c_str());
  std::printf("  memory: map and skip structures %.3g MiB, with depths and tables %.3g MiB (%s)\n",
              map.bytes() / 1048576.0, stats.device_bytes / 1048576.0, backend == Backend::Cuda ? "on the GPU" : "host");
  std::printf("render: %.3f s marching, %llu table lookups beyond tau_max (clamped); total %.2f s\n", stats.seconds,
              (unsigned long long)stats.table_clamps, seconds_since(start));
  std::printf("wrote %s\n", out.c_str());
}

}  // namespace nebula::app
