// CPU launch of the path tracer: one TBB task per image row.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>

#include "core/error.h"
#include "core/progress.h"
#include "validation/truth_renderer.h"

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
  for (const TruthStar& s : in.stars)
    if (s.power.size() != in.bands.size()) throw Error("truth: a star lacks band powers");
  if (in.spp < 2) throw Error("--spp: at least 2 samples per pixel (the variance needs two)");
  if (in.max_orders < 0) throw Error("--max-orders: must be 0 (all) or positive");
  if (in.roulette_start < 1) throw Error("truth: roulette_start must be at least 1");
  if (in.majorant_block < 1 || in.majorant_block > 256) throw Error("--majorant-block: must be 1 to 256 voxels");
  if (in.camera.width < 1 || in.camera.height < 1) throw Error("truth: the camera has no pixels");
}

HostPathScene prepare_path_scene(const TruthInputs& in) {
  validate(in);
  HostPathScene h;
  h.majorant = build_majorant_grid(*in.density, in.majorant_block);
  h.stars.resize(in.stars.size());
  for (size_t k = 0; k < in.stars.size(); ++k) {
    h.stars[k].position = in.stars[k].position;
    for (int b = 0; b < kMaxBands; ++b) h.stars[k].power[b] = b < int(in.bands.size()) ? in.stars[k].power[b] : 0.0f;
  }
  PathScene& s = h.scene;
  s.density = in.density->view();
  s.majorant = h.majorant.view();
  s.n_bands = static_cast<int>(in.bands.size());
  for (int b = 0; b < kMaxBands; ++b) {
    const bool used = b < s.n_bands;
    s.extinction_ratio[b] = used ? in.bands[b].extinction_ratio : 1.0f;
    s.albedo[b] = used ? in.bands[b].albedo : 0.0f;
    s.g[b] = used ? in.bands[b].g : 0.0f;
    s.emission[b] = used && in.bands[b].emission ? in.bands[b].emission->data() : nullptr;
  }
  s.stars = h.stars.data();
  s.n_stars = static_cast<int>(h.stars.size());
  s.seed = in.seed;
  s.max_orders = in.max_orders;
  s.roulette_start = in.roulette_start;
  s.exact_transmittance = in.exact_transmittance;
  s.equiangular = in.equiangular;
  return h;
}

TruthOutput render_truth_cpu(const TruthInputs& in) {
  HostPathScene host = prepare_path_scene(in);
  const PathScene& s = host.scene;
  std::vector<std::string> names;
  for (const TruthBand& b : in.bands) names.push_back(b.name);
  TruthOutput out;
  out.image = Image(in.camera.width, in.camera.height, names);
  out.variance = Image(in.camera.width, in.camera.height, names);
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
