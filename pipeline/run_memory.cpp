#include <algorithm>
#include <string>

#include "core/error.h"
#include "core/memory.h"
#include "pipeline/render_scene.h"

namespace nebula {

RunMemory estimate_run_memory(const Scene& scene, RunKind kind) {
  RunMemory m;
  const double bands = double(scene.bands.size());
  const double pixels = double(scene.camera.width) * double(scene.camera.height);
  // The image per band in float, and as much again for the writer's copy (the
  // ground truth keeps a variance image too, and per-pixel accumulators).
  const double image = pixels * bands * 4;
  m.parts.push_back({"image " + std::to_string(scene.camera.width) + " x " + std::to_string(scene.camera.height) +
                         " x " + to_text(bands) + " bands",
                     kind == RunKind::Truth ? image * 5 : image * 2});
  // The fast renderers trace k^2 rays per pixel as an image k times finer.
  if (kind == RunKind::Fast && scene.samples_per_pixel > 1)
    m.parts.push_back({"the " + std::to_string(scene.samples_per_pixel) + " samples per pixel's finer image",
                       image * scene.samples_per_pixel});
  const double cells = double(scene.diffuse.cells);
  const int order = resolved_order(scene.diffuse, scene.dust.g);
  const double coefficients = double((order + 1) * (order + 1));
  if (scene.axial) {
    const AxialSpec& a = *scene.axial;
    if (a.source == "synthetic")
      m.parts.push_back({"axial map", double(a.nx) * double(a.nr) * (1 + bands) * 4 * 2});
    if (kind == RunKind::Truth) {
      // The map voxelized, at most 256^3 (the default --axial-voxels), with
      // its emission planes and the majorant grid.
      m.parts.push_back({"voxelized map", 256.0 * 256 * 256 * 4 * (2 + bands)});
    } else if (scene.multiple_scattering == MultipleScattering::Diffuse && !scene.stars.empty()) {
      // The photons' grid of 2 cells' worth of voxels per cell, its majorant,
      // and the 3D field's sums (8 bytes) and harmonics.
      const double grid = 8 * cells * cells * cells;
      m.parts.push_back({"axial diffuse bake", grid * 4 * 2 + cells * cells * cells * coefficients * bands * 12});
    }
  } else {
    const double voxels = double(scene.density.shape.count());
    m.parts.push_back({"grids", voxels * 4 * (1 + double(scene.emission.size()))});
    if (kind == RunKind::Fast) {
      m.parts.push_back({"star bakes", voxels * 4 * double(scene.stars.size())});
      if (scene.multiple_scattering == MultipleScattering::Pyramid)
        m.parts.push_back({"pyramid levels", voxels * 4 * (1 + double(scene.stars.size())) / 7 + image / 3});
      if (scene.multiple_scattering == MultipleScattering::Diffuse) {
        // The field (kept, and packed for the kernels), its sums while baking
        // (8 bytes each), and each view's light per voxel and band.
        // Zonal degrees add theirs per zonal star (at most 4).
        const int zonal = resolved_zonal(scene.diffuse, scene.dust.g);
        const double zonal_coefficients =
            zonal > order ? double(zonal - order) * double(std::min<size_t>(scene.stars.size(), 4)) : 0.0;
        m.parts.push_back({"diffuse field", cells * cells * cells * (coefficients + zonal_coefficients) * bands * (4 * 2 + 8)});
        m.parts.push_back({"diffuse light per view (light and forward peak)", voxels * 4 * 2 * bands});
      }
    } else {
      m.parts.push_back({"majorant grid", voxels * 4});
    }
  }
  for (const auto& part : m.parts) m.bytes += part.second;
  return m;
}

void check_run_memory(const Scene& scene, RunKind kind) {
  const RunMemory m = estimate_run_memory(scene, kind);
  const std::string over = over_memory_limit(m.bytes);
  if (over.empty()) return;
  std::string parts;
  for (const auto& [what, bytes] : m.parts) parts += (parts.empty() ? "" : ", ") + what + " " + bytes_text(bytes);
  throw Error(scene.path + ": the run " + over + " (" + parts + "); lower camera.width/height or the grid's size");
}

}  // namespace nebula
