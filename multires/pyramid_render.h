#pragma once
// Wide-range multiple scattering with the resolution pyramid of the 2005
// paper (section 4.2; DESIGN.md section 3): volume level j (volume_pyramid.h)
// lit by its own bake and rendered by the ray marcher (raycast/) at 1/2^j of
// the resolution; the clipped difference images (image_pyramid.h) are
// up-sampled and added to the level-0 image, on the host or, with every level
// image kept on the device, on the GPU (pyramid_render_cuda.cu).
#include <cstdint>
#include <vector>

#include "core/backend.h"
#include "core/grid.h"
#include "core/image.h"
#include "raycast/renderer.h"

namespace nebula {

struct PyramidLevelReport {
  int level = 0;
  GridShape shape;
  int width = 0, height = 0;
  double bake_seconds = 0;    // this level's star bake (0 for level 0: baked by the caller)
  double pyramid_seconds = 0; // building this level's volume and emission from the level below
  double render_seconds = 0;  // marching (CUDA events on the GPU)
  uint64_t table_clamps = 0;  // lookups beyond the table's tau range (coarse voxels are thicker)
};

struct PyramidResult {
  Image image;                // I_0 + the up-sampled clipped differences
  std::vector<Image> levels;  // I_0 .. I_n (I_j at 1/2^j resolution); on the GPU, and with no coarser levels, only when asked for
  std::vector<PyramidLevelReport> report;  // one per level, 0 first
  double combine_seconds = 0;              // host clock on the CPU, CUDA events on the GPU
};

// The coarser levels' volumes, emission and star bakes: what a camera move
// leaves unchanged (built once, rendered every frame).
struct PyramidLevelData {
  DensityGrid density;
  std::vector<std::vector<float>> emission;  // per band; empty where the band has none
  std::vector<std::vector<float>> depth;     // per star, baked V-band depth
  PyramidLevelReport report;                 // build and bake times filled in
};
struct PreparedPyramid {
  std::vector<PyramidLevelData> levels;  // levels 1..n (level 0 is the caller's)
};

// `in` is the level-0 render (its stars' depths baked by the caller). Throws
// Error for levels outside 0..max_pyramid_levels(in.density->shape).
PreparedPyramid prepare_pyramid(const RenderInputs& in, int levels, Backend backend);

// One frame: level 0 from `in`, the coarser levels from `prepared` (built for
// the same grid, bands and stars), each at 1/2^j of in.camera's resolution.
// No levels gives exactly render(in, backend). On the GPU the level images
// stay on the device and are combined there; keep_levels downloads them too.
PyramidResult render_pyramid(const RenderInputs& in, const PreparedPyramid& prepared, Backend backend,
                             bool keep_levels = false);
PyramidResult render_pyramid_cuda(const RenderInputs& in, const PreparedPyramid& prepared, bool keep_levels);

// Level j's render inputs: `in` with the level's grid, emission and bakes and
// the camera `camera` (in.camera made coarser j times).
RenderInputs level_inputs(const RenderInputs& in, const PyramidLevelData& level, const Camera& camera);

// Both steps.
PyramidResult render_pyramid(const RenderInputs& in, int levels, Backend backend, bool keep_levels = false);

}  // namespace nebula
