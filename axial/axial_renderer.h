#pragma once
// Renders an axial map (axial_map.h) lit by stars on its axis, on the CPU
// (TBB, one task per image row) or the GPU (one CUDA thread per pixel); both
// run march_axial_ray (axial_march.h) over the scene assembled once by
// assemble_axial_scene (axial_scene.h).
#include <string>
#include <vector>

#include "axial/axial_map.h"
#include "axial/axial_march.h"
#include "core/backend.h"
#include "core/bands.h"
#include "core/camera.h"
#include "core/image.h"
#include "diffuse/diffuse_field.h"
#include "tables/scattering_table.h"

namespace nebula {

class Progress;

// A band as the axial marcher reads it (its emission is in the map). It
// scatters where it has a table; one is required when albedo > 0 and there
// are stars.
struct AxialRenderBand : Band {
  const ScatteringTable* table = nullptr;
};

struct AxialRenderInputs {
  const AxialMap* map = nullptr;  // emission, if any, per band in the bands' order
  std::vector<AxialRenderBand> bands;
  std::vector<BakedStar> stars;  // on the map's axis; depth_v per texel (axial_bake.h)
  // Light scattered between cells (axial_diffuse.h), baked for this map,
  // these bands and stars; null: single scattering (and the table's own).
  const DiffuseField* diffuse = nullptr;
  // Colour and shape deformations (axial_deform.h; Khalass 2021 section 3.2).
  // The stars' depths and the diffuse field stay those of the undeformed map.
  AxialDeformSettings deform;
  Camera camera;
  float exposure = 1.0f;
  bool star_pixels = true;  // the pixels at each star's image with many rays each (illumination/star_pixels.h)
  float min_transmittance = 1e-4f;
  float step = 0;  // h in world units; 0 means half a texel
  AxialSkip skip = AxialSkip::Distance;
  bool step_aside = true;  // march naively when the map has no empty texel (effective_skip)
  Progress* progress = nullptr;  // CPU only, advanced in image rows; may be null
};

struct AxialRenderStats {
  double seconds = 0;  // marching only (CUDA events on the GPU)
  uint64_t table_clamps = 0;
  size_t device_bytes = 0;  // the map, skip structures, depths and tables the march reads
  uint64_t samples = 0; // samples the rays stepped through (CPU only)
  AxialSkip skip_used = AxialSkip::Naive;  // effective_skip()
};

// Throws Error naming the problem (sizes, a star off the axis, a bad step).
void validate(const AxialRenderInputs& in);
float effective_step(const AxialRenderInputs& in);
// The mode the march runs: in.skip, except the naive march when the map has
// no empty texel (nothing can be skipped, so the checks would only cost).
AxialSkip effective_skip(const AxialRenderInputs& in);
// Every mode, naive first.
const std::vector<AxialSkip>& axial_skip_modes();
// "naive", "empty", "global_max", "omega", "omega_multi", "distance", "thesis_omega_max",
// "thesis_omega_large", "thesis_omega_multi"; Error naming `option` otherwise.
AxialSkip parse_axial_skip(const std::string& text, const std::string& option);

Image render_axial(const AxialRenderInputs& in, Backend backend, AxialRenderStats* stats = nullptr);
Image render_axial_cpu(const AxialRenderInputs& in, AxialRenderStats* stats);
Image render_axial_cuda(const AxialRenderInputs& in, AxialRenderStats* stats);

}  // namespace nebula
