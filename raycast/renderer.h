#pragma once
// Renders an image of a voxel grid lit by stars, on the CPU (TBB) or the GPU
// (CUDA); both run march_ray per pixel.
#include <string>
#include <vector>

#include "core/backend.h"
#include "core/grid.h"
#include "core/image.h"
#include "raycast/camera.h"
#include "raycast/ray_march.h"
#include "tables/scattering_table.h"

namespace nebula {

class Progress;

struct RenderBand {
  std::string name;             // "B", "V", "R"
  float extinction_ratio = 1;   // A_b / A_V
  float albedo = 0.6f;
  const ScatteringTable* table = nullptr;  // required when albedo > 0
  const std::vector<float>* emission = nullptr;  // j per voxel, or null
};

struct RenderStar {
  Vec3 position;
  std::vector<float> power;            // per band, L_sun
  const std::vector<float>* depth_v;   // baked V-band depth per voxel
};

struct RenderInputs {
  const DensityGrid* density = nullptr;
  std::vector<RenderBand> bands;
  std::vector<RenderStar> stars;
  Camera camera;
  float exposure = 1.0f;
  float min_transmittance = 1e-4f;
  MarchMode mode;  // exact traversal by default; step_voxels > 0: smooth display mode
  Progress* progress = nullptr;  // advanced in image rows (CPU); may be null
};

struct RenderStats {
  double seconds = 0;        // marching only (CUDA events on the GPU)
  uint64_t table_clamps = 0; // lookups beyond the table's tau range
};

// Throws Error on inconsistent inputs (missing table, sizes that disagree).
Image render(const RenderInputs& in, Backend backend, RenderStats* stats = nullptr);
Image render_cpu(const RenderInputs& in, RenderStats* stats);
Image render_cuda(const RenderInputs& in, RenderStats* stats);

// Host-side checks shared by both backends.
void validate(const RenderInputs& in);

}  // namespace nebula
