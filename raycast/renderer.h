#pragma once
// Renders an image of a voxel grid lit by stars, on the CPU (TBB) or the GPU
// (CUDA); both run march_ray per pixel over the scene assembled once by
// assemble_march_scene (raycast/march_scene.h).
#include <string>
#include <vector>

#include "core/backend.h"
#include "core/bands.h"
#include "core/camera.h"
#include "core/grid.h"
#include "core/image.h"
#include "diffuse/diffuse_field.h"
#include "raycast/ray_march.h"
#include "tables/scattering_table.h"

namespace nebula {

class Progress;

// A band as the ray marcher reads it: a band with albedo > 0 scatters and
// needs a table; a band with albedo 0 reads none.
struct RenderBand : Band {
  const ScatteringTable* table = nullptr;
  const std::vector<float>* emission = nullptr;  // j per voxel, or null
};

struct RenderInputs {
  const DensityGrid* density = nullptr;
  std::vector<RenderBand> bands;
  std::vector<BakedStar> stars;  // depth_v: the baked V-band depth per voxel
  // Light scattered between voxels (diffuse/diffuse_bake.h), baked for this
  // grid and these bands; null: none (single scattering and each voxel's own
  // multiple scattering only).
  const DiffuseField* diffuse = nullptr;
  Camera camera;
  float exposure = 1.0f;
  float min_transmittance = 1e-4f;
  MarchMode mode;  // exact traversal by default; step_voxels > 0: smooth display mode
  bool star_pixels = true;  // the pixels at each star's image with many rays each (illumination/star_pixels.h)
  Progress* progress = nullptr;  // advanced in image rows (CPU); may be null
};

struct RenderStats {
  double seconds = 0;        // marching only (CUDA events on the GPU)
  uint64_t table_clamps = 0; // lookups beyond the table's tau range
};

// Whether a frame of `in` marches the pixels at its stars' images with many
// rays each: asked for, stars present, and the exact traversal (not the smooth
// mode or the preview), as dispatch_march chooses. The CPU and CUDA renderers
// and the run report all ask this.
inline bool marches_star_pixels(const RenderInputs& in) {
  return in.star_pixels && !in.stars.empty() && !in.mode.voxel_sources && !(in.mode.step_voxels > 0.0f);
}

// Throws Error on inconsistent inputs (missing table, sizes that disagree).
Image render(const RenderInputs& in, Backend backend, RenderStats* stats = nullptr);
Image render_cpu(const RenderInputs& in, RenderStats* stats);
Image render_cuda(const RenderInputs& in, RenderStats* stats);

// The CUDA path's frame for renderers built on this one (multires/): marches
// every pixel of in.camera into `device_pixels` (bands x height x width,
// device memory), adds the table clamps to *device_clamps (device memory) and
// returns the kernel's time (CUDA events).
double render_cuda_to_device(const RenderInputs& in, float* device_pixels, unsigned long long* device_clamps);

// Host-side checks shared by both backends.
void validate(const RenderInputs& in);

// The diffuse field's per-view pass alone (raycast/diffuse_light.h), for
// renderers that march on their own (spectral/, through the pipeline): each
// voxel's light towards in.camera's eye and its forward peak, per band with a
// field ([band][voxel]; empty for a band without one). The same numbers the
// march of render() reads. On the CPU they are host arrays; from CUDA they
// stay on the device (device_light, device_peak: one array of the grid's
// voxels per band with a field), the host arrays empty. Throws Error without a field.
struct DiffuseLightArrays {
  std::vector<std::vector<float>> light, peak;
  std::vector<DeviceMirror> device_light, device_peak;
};
DiffuseLightArrays diffuse_light_arrays(const RenderInputs& in, Backend backend);
DiffuseLightArrays diffuse_light_arrays_cuda(const RenderInputs& in);

}  // namespace nebula
