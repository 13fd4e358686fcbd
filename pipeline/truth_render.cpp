// The ground truth on a scene's 3D grid: the same bands, stars, emission and
// camera as the fast renderer, traced by truth/.
#include <chrono>
#include <memory>

#include "axial/axial_diffuse.h"
#include "core/error.h"
#include "pipeline/axial_map_source.h"
#include "core/progress.h"
#include "pipeline/render_scene.h"
#include "pipeline/run_setup.h"
#include "truth/truth_renderer.h"

namespace nebula {

using namespace pipeline_detail;

namespace {

// An axial map as the truth traces it: voxelized in its own frame (the axis
// along z from 0; axial/axial_diffuse.h, each voxel the mean of its texels),
// with the stars and the camera moved into that frame by the same rigid
// motion, which changes no image.
struct AxialFrame {
  DensityGrid density;
  std::vector<std::vector<float>> emission;
  Vec3 origin, rows[3];  // world -> frame: p' = R (p - origin), R's rows
  Vec3 point(Vec3 p) const { return vector(p - origin); }
  Vec3 vector(Vec3 v) const { return {dot(rows[0], v), dot(rows[1], v), dot(rows[2], v)}; }
};

AxialFrame axial_frame(const Scene& scene, int voxels, const std::shared_ptr<const AxialMap>& given) {
  if (voxels < 8 || voxels > 2048) throw ParameterError("axial_voxels", "must be 8 to 2048, got " + std::to_string(voxels));
  const AxialMap map = given ? place_axial_map(scene, *given) : build_axial_map(scene);
  AxialFrame f;
  const float longest = std::max(map.length(), 2.0f * map.radius());
  f.density = voxelize_axial_frame(map, longest / float(voxels), &f.emission);
  f.origin = map.origin;
  Vec3 p, q;
  orthonormal_frame(map.axis, p, q);
  f.rows[0] = p;
  f.rows[1] = cross(map.axis, p);  // (p, axis x p, axis) is right-handed: no mirror image
  f.rows[2] = map.axis;
  return f;
}

}  // namespace

TruthRenderOutput truth_scene(const Scene& scene, const TruthOptions& o) {
  const auto start = std::chrono::steady_clock::now();
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
  AxialFrame frame;
  if (scene.axial) {
    // The truth traces the map's voxelization, which has no deformations:
    // refused rather than silently tracing another nebula.
    if (scene.axial->colour_deform.on || scene.axial->shape_deform.on)
      throw ParameterError(scene.path + ": axial." +
                               (scene.axial->colour_deform.on ? "colour_deform" : "shape_deform"),
                           "the path tracer traces the undeformed map; deformations are for `nebula render`");
    frame = axial_frame(scene, o.axial_voxels, o.axial_map);
    in.density = &frame.density;
    for (size_t b = 0; b < sb.bands.size(); ++b)
      in.bands[b].emission = frame.emission.empty() ? nullptr : &frame.emission[b];
    for (StarLight& s : in.stars) s.position = frame.point(s.position);
    CameraSettings cs = scene.camera;
    cs.position = frame.point(cs.position);
    cs.look_at = frame.point(cs.look_at);
    cs.up = frame.vector(cs.up);
    in.camera = make_camera(cs);
  }
  in.exposure = 1.0f;  // science pixels: the exposure goes in the metadata
  in.spp = o.spp;
  in.pixel_side = samples_per_pixel_side(scene.samples_per_pixel);
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
  if (!scene.axial) draw_scene_stars(scene, sb, camera, 1.0, result.image);

  TruthRenderOutput out;
  out.image = std::move(result.image);
  out.variance = std::move(result.variance);
  const std::string transmittance = o.exact_transmittance ? "exact" : "ratio";
  const std::string traced =
      scene.axial ? " on the map voxelized to " + std::to_string(frame.density.shape.nx) + "x" +
                        std::to_string(frame.density.shape.ny) + "x" + std::to_string(frame.density.shape.nz)
                  : "";
  const std::string mode = "truth spp " + std::to_string(o.spp) + " seed " + std::to_string(o.seed) + " " +
                           transmittance + " transmittance" + (o.equiangular ? " equiangular" : "") +
                           (o.max_orders ? " orders<=" + std::to_string(o.max_orders) : "") + traced;
  out.metadata = scene_metadata(scene, sb, scene.camera, mode);
  out.metadata.entries.push_back({"pixel_samples", scene.samples_per_pixel});
  out.variance_metadata = out.metadata;
  out.variance_metadata.units = kRadianceVarianceUnit;  // of the pixel mean
  RunReport& r = out.report;
  r = begin_report(scene, sb, "truth", o.backend);
  r.mode = mode;
  r.truth = TruthReport{o.spp, o.seed, o.max_orders, transmittance, o.equiangular, result.paths, result.counters,
                        frame.density.shape};
  r.render_seconds = result.seconds;
  r.total_seconds = seconds_since(start);
  return out;
}

}  // namespace nebula
