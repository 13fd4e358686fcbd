#pragma once
// The ground-truth image of a scene: path_tracer.h per pixel, on the CPU
// (TBB, one task per row) or the GPU (one CUDA thread per pixel, or several
// sharing its samples when the image is small), with the variance of every
// pixel's mean beside the image.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/backend.h"
#include "core/bands.h"
#include "core/camera.h"
#include "core/grid.h"
#include "core/image.h"
#include "core/placement.h"
#include "montecarlo/majorant_grid.h"
#include "truth/path_tracer.h"

namespace nebula {

class Progress;

// A band as the path tracer reads it: the dust's albedo and g, and emission.
struct TruthBand : Band {
  const std::vector<float>* emission = nullptr;  // j per voxel, or null
};

struct TruthInputs {
  const DensityGrid* density = nullptr;
  std::vector<TruthBand> bands;
  std::vector<StarLight> stars;
  Camera camera;
  float exposure = 1.0f;
  int spp = 16;            // samples per pixel and band, >= 2
  int pixel_side = 1;      // pixel-area sampling: side x side strata (1: the pixel's centre); spp a multiple of side^2
  bool star_strata = true;  // a stratum holding a star's image samples about it (path_tracer.h sample_stratum)
  uint64_t seed = 1;
  int max_orders = 0;      // 0: all orders (the truth)
  int roulette_start = 3;
  int majorant_block = 4;  // voxels per majorant block edge
  bool exact_transmittance = false;  // NEE transmittance by the exact voxel sum (no noise) instead of ratio tracking
  bool equiangular = false;  // NEE also from equiangular samples towards each star (MIS): stars inside dust
  Progress* progress = nullptr;  // advanced in image rows (CPU); may be null
  // CUDA: how many threads share each pixel's samples (0: as many as fill the
  // GPU with threads; a 64 x 64 image has too few pixels for one each).
  // Changes only the order of the double sums, never a sample.
  int gpu_threads_per_pixel = 0;
};

struct TruthOutput {
  Image image;     // mean radiance per pixel and band (exposure applied)
  Image variance;  // variance of that mean, same layout
  double seconds = 0;  // tracing only (CUDA events on the GPU)
  uint64_t paths = 0;  // pixels with a ray x spp x bands
  int threads_per_pixel = 1;  // how many threads shared each pixel's samples (CUDA; 1 on the CPU)
  PathCounters counters;
};

// Throws ParameterError naming the field of a bad setting (spp, max_orders,
// majorant_block, ...), Error on inconsistent inputs.
void validate(const TruthInputs& in);
TruthOutput render_truth(const TruthInputs& in, Backend backend);
TruthOutput render_truth_cpu(const TruthInputs& in);
TruthOutput render_truth_cuda(const TruthInputs& in);

// A path's kernel scene, assembled once for both backends (core/placement.h)
// from validated inputs and their majorant grid: the density, majorant and
// emission arrays and the star views placed on the host as they are, or
// uploaded for CUDA.
template <class Place>
PathScene assemble_path_scene(const TruthInputs& in, const MajorantGrid& majorant, Place& place) {
  std::vector<TruthStarView> stars(in.stars.size());
  for (size_t k = 0; k < in.stars.size(); ++k) {
    stars[k].position = in.stars[k].position;
    for (int b = 0; b < kMaxBands; ++b) stars[k].power[b] = b < int(in.bands.size()) ? in.stars[k].power[size_t(b)] : 0.0f;
    if (const std::optional<ImagePoint> at = project_point(in.camera, in.stars[k].position)) {
      stars[k].image_x = static_cast<float>(at->x);
      stars[k].image_y = static_cast<float>(at->y);
      stars[k].in_image = true;
    }
  }
  PathScene s;
  s.density = {in.density->shape, place.place(in.density->tau_v, in.density->device_tau_v)};
  s.majorant = majorant.view();
  s.majorant.max_tau_v = place.place(majorant.max_tau_v);
  s.majorant.min_tau_v = place.place(majorant.min_tau_v);
  s.n_bands = static_cast<int>(in.bands.size());
  for (int b = 0; b < kMaxBands; ++b) {
    const bool used = b < s.n_bands;
    s.extinction_ratio[b] = used ? in.bands[size_t(b)].extinction_ratio : 1.0f;
    s.albedo[b] = used ? in.bands[size_t(b)].albedo : 0.0f;
    s.g[b] = used ? in.bands[size_t(b)].g : 0.0f;
    s.emission[b] = used && in.bands[size_t(b)].emission ? place.place(*in.bands[size_t(b)].emission) : nullptr;
  }
  s.stars = place.keep(std::move(stars));
  s.n_stars = static_cast<int>(in.stars.size());
  s.seed = in.seed;
  s.max_orders = in.max_orders;
  s.pixel_side = in.pixel_side;
  s.star_strata = in.star_strata;
  s.roulette_start = in.roulette_start;
  s.exact_transmittance = in.exact_transmittance;
  s.equiangular = in.equiangular;
  return s;
}

// The host copy of what a path needs, for the CPU launch and for tests that
// call trace_path: validates, builds the majorant grid and assembles.
struct HostPathScene {
  MajorantGrid majorant;
  HostPlacement place;
  PathScene scene;
};
HostPathScene prepare_path_scene(const TruthInputs& in);

}  // namespace nebula
