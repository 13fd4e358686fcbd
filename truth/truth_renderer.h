#pragma once
// The ground-truth image of a scene: path_tracer.h per pixel, on the CPU
// (TBB, one task per row) or the GPU (one CUDA thread per pixel), with the
// variance of every pixel's mean beside the image.
#include <cstdint>
#include <string>
#include <vector>

#include "core/backend.h"
#include "core/grid.h"
#include "core/image.h"
#include "raycast/camera.h"
#include "validation/majorant_grid.h"
#include "validation/path_tracer.h"

namespace nebula {

class Progress;

struct TruthBand {
  std::string name;
  float extinction_ratio = 1;  // A_b / A_V
  float albedo = 0.6f;
  float g = 0.6f;
  const std::vector<float>* emission = nullptr;  // j per voxel, or null
};

struct TruthStar {
  Vec3 position;
  std::vector<float> power;  // per band, L_sun
};

struct TruthInputs {
  const DensityGrid* density = nullptr;
  std::vector<TruthBand> bands;
  std::vector<TruthStar> stars;
  Camera camera;
  float exposure = 1.0f;
  int spp = 16;            // samples per pixel and band, >= 2
  uint64_t seed = 1;
  int max_orders = 0;      // 0: all orders (the truth)
  int roulette_start = 3;
  int majorant_block = 4;  // voxels per majorant block edge
  bool exact_transmittance = false;  // NEE transmittance by the exact voxel sum (no noise) instead of ratio tracking
  bool equiangular = false;  // NEE also from equiangular samples towards each star (MIS): stars inside dust
  Progress* progress = nullptr;  // advanced in image rows (CPU); may be null
};

struct TruthOutput {
  Image image;     // mean radiance per pixel and band (exposure applied)
  Image variance;  // variance of that mean, same layout
  double seconds = 0;  // tracing only (CUDA events on the GPU)
  uint64_t paths = 0;  // pixels with a ray x spp x bands
  PathCounters counters;
};

// Throws Error naming the field on inconsistent inputs.
void validate(const TruthInputs& in);
TruthOutput render_truth(const TruthInputs& in, Backend backend);
TruthOutput render_truth_cpu(const TruthInputs& in);
TruthOutput render_truth_cuda(const TruthInputs& in);

// The host copy of what a path needs (the majorant grid and the stars
// owned here), for the CPU launch and for tests that call trace_path.
struct HostPathScene {
  MajorantGrid majorant;
  std::vector<TruthStarView> stars;
  PathScene scene;
};
HostPathScene prepare_path_scene(const TruthInputs& in);

}  // namespace nebula
