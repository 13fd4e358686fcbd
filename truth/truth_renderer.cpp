// CPU launch of the path tracer: one TBB task per image row.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>

#include "core/error.h"
#include "core/progress.h"
#include "truth/truth_renderer.h"

namespace nebula {

void validate(const TruthInputs& in) {
  if (!in.density) throw Error("truth: no density grid");
  const size_t voxels = in.density->shape.count();
  if (voxels == 0 || in.density->tau_v.size() != voxels) throw Error("truth: density has the wrong number of voxels");
  if (in.bands.empty() || in.bands.size() > size_t(kMaxBands))
    throw Error("truth: 1 to " + std::to_string(kMaxBands) + " bands required");
  for (const TruthBand& b : in.bands) {
    if (!(b.albedo >= 0.0f && b.albedo <= 1.0f)) throw Error("truth: band " + b.name + ": albedo must be in [0, 1]");
    if (!(b.g > -1.0f && b.g < 1.0f)) throw Error("truth: band " + b.name + ": g must be in (-1, 1)");
    if (!(b.extinction_ratio > 0.0f)) throw Error("truth: band " + b.name + ": extinction ratio must be positive");
    if (b.emission && b.emission->size() != voxels)
      throw Error("truth: emission of band " + b.name + " does not match the density grid");
  }
  for (const StarLight& s : in.stars)
    if (s.power.size() != in.bands.size()) throw Error("truth: a star lacks band powers");
  if (in.spp < 2) throw ParameterError("spp", "at least 2 samples per pixel (the variance needs two)");
  if (in.pixel_side < 1 || in.pixel_side > 16) throw ParameterError("pixel_side", "must be 1 to 16");
  if (in.spp % (in.pixel_side * in.pixel_side) != 0)
    throw ParameterError("spp", std::to_string(in.spp) + " is not a multiple of the " +
                                    std::to_string(in.pixel_side * in.pixel_side) +
                                    " strata of render.samples_per_pixel (each stratum gets as many samples)");
  if (in.max_orders < 0) throw ParameterError("max_orders", "must be 0 (all) or positive");
  if (in.roulette_start < 1) throw ParameterError("roulette_start", "must be at least 1");
  if (in.majorant_block < 1 || in.majorant_block > 256) throw ParameterError("majorant_block", "must be 1 to 256 voxels");
  if (in.camera.width < 1 || in.camera.height < 1) throw Error("truth: the camera has no pixels");
}

HostPathScene prepare_path_scene(const TruthInputs& in) {
  validate(in);
  HostPathScene h;
  h.majorant = build_majorant_grid(*in.density, in.majorant_block);
  h.scene = assemble_path_scene(in, h.majorant, h.place);
  return h;
}

TruthOutput render_truth_cpu(const TruthInputs& in) {
  HostPathScene host = prepare_path_scene(in);
  const PathScene& s = host.scene;
  TruthOutput out;
  out.image = Image(in.camera.width, in.camera.height, band_names(in.bands));
  out.variance = Image(in.camera.width, in.camera.height, band_names(in.bands));
  std::atomic<uint64_t> vertices{0}, tentative{0}, capped{0}, rays{0};
  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<int>(0, in.camera.height), [&](const auto& rows) {
    PathCounters c;
    uint64_t local_rays = 0;
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < in.camera.width; ++x) {
        float mean[kMaxBands], var[kMaxBands];
        trace_pixel(s, in.camera, in.exposure, x, y, in.spp, mean, var, c);
        Vec3 o, d;
        local_rays += in.camera.ray(x, y, o, d);
        for (int b = 0; b < s.n_bands; ++b) {
          out.image.at(b, x, y) = mean[b];
          out.variance.at(b, x, y) = var[b];
        }
      }
    vertices += c.vertices;
    tentative += c.tentative;
    capped += c.capped;
    rays += local_rays;
    if (in.progress) in.progress->add(rows.size());
  });
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.paths = rays.load() * uint64_t(in.spp) * in.bands.size();
  out.counters.vertices = vertices;
  out.counters.tentative = tentative;
  out.counters.capped = capped;
  return out;
}

TruthOutput render_truth(const TruthInputs& in, Backend backend) {
  return backend == Backend::Cuda ? render_truth_cuda(in) : render_truth_cpu(in);
}

}  // namespace nebula
