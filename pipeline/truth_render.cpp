// The ground truth on a scene's 3D grid: the same bands, stars, emission and
// camera as the fast renderer, traced by truth/.
#include <chrono>
#include <memory>

#include "core/error.h"
#include "core/progress.h"
#include "pipeline/render_scene.h"
#include "pipeline/run_setup.h"
#include "truth/truth_renderer.h"

namespace nebula {

using namespace pipeline_detail;

TruthRenderOutput truth_scene(const Scene& scene, const TruthOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  if (scene.axial)
    throw Error(scene.path + ": axial: the ground truth traces 3D grids only; an axial map has none to trace");
  validate_scene(scene);
  check_run_memory(scene, RunKind::Truth);
  const Camera camera = make_camera(scene.camera);
  const SceneBands sb = scene_bands(scene);

  TruthInputs in;
  in.density = &scene.density;
  for (size_t b = 0; b < sb.bands.size(); ++b)
    in.bands.push_back(TruthBand{sb.bands[b], scene.emission.empty() ? nullptr : &scene.emission[b]});
  in.stars = sb.stars;
  in.camera = camera;
  in.exposure = static_cast<float>(scene.camera.exposure);
  in.spp = o.spp;
  in.seed = o.seed;
  in.max_orders = o.max_orders;
  in.majorant_block = o.majorant_block;
  in.exact_transmittance = o.exact_transmittance;
  in.equiangular = o.equiangular;
  validate(in);
  std::unique_ptr<Progress> bar;
  if (o.progress && o.backend == Backend::Cpu) bar = std::make_unique<Progress>("truth", uint64_t(camera.height));
  in.progress = bar.get();
  TruthOutput result = render_truth(in, o.backend);
  if (bar) bar->finish();
  // Stars seen directly: the same deterministic drawing as the fast renderer
  // (exact transmittance, a Gaussian PSF); no variance.
  draw_scene_stars(scene, sb, camera, scene.camera.exposure, result.image);

  TruthRenderOutput out;
  out.image = std::move(result.image);
  out.variance = std::move(result.variance);
  const std::string transmittance = o.exact_transmittance ? "exact" : "ratio";
  const std::string mode = "truth spp " + std::to_string(o.spp) + " seed " + std::to_string(o.seed) + " " +
                           transmittance + " transmittance" + (o.equiangular ? " equiangular" : "") +
                           (o.max_orders ? " orders<=" + std::to_string(o.max_orders) : "");
  out.metadata = scene_metadata(scene, sb, scene.camera, mode);
  out.variance_metadata = out.metadata;
  out.variance_metadata.units = "(L_sun pc^-2 sr^-1 x exposure)^2, variance of the pixel mean";
  RunReport& r = out.report;
  r = begin_report(scene, sb, "truth", o.backend);
  r.mode = mode;
  r.truth = TruthReport{o.spp, o.seed, o.max_orders, transmittance, o.equiangular, result.paths, result.counters};
  r.render_seconds = result.seconds;
  r.total_seconds = seconds_since(start);
  return out;
}

}  // namespace nebula
