#pragma once
// The render pipeline (DESIGN.md section 2): scene -> bands (extinction
// ratios, star band powers) -> tables (read, cached or generated) -> bakes ->
// render (3D grid with its pyramid levels, axial map, or the ground truth) ->
// image, its metadata and the run report. The one entry point the command
// line, the tests and any other front end call; it prints nothing (progress
// bars aside) and names scene keys or option fields in its errors
// (ParameterError), never command-line options.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "axial/axial_map.h"
#include "core/backend.h"
#include "core/image.h"
#include "diffuse/diffuse_field.h"
#include "illumination/optical_depth_bake.h"
#include "imageio/image_output.h"
#include "multires/pyramid_render.h"
#include "pipeline/run_report.h"
#include "pipeline/scene_bands.h"
#include "pipeline/table_source.h"
#include "raycast/renderer.h"
#include "scene/scene.h"

namespace nebula {

// What a run will allocate, estimated from the scene before any work: the
// image(s), the grids, the star bakes, the diffuse field or pyramid levels
// (the largest parts; small ones such as tables are left out).
enum class RunKind { Fast, Truth };
struct RunMemory {
  double bytes = 0;
  std::vector<std::pair<std::string, double>> parts;  // what, bytes
};
RunMemory estimate_run_memory(const Scene& scene, RunKind kind);

// Throws Error "<scene>: the run needs X, more than the limit of Y (half the
// physical memory) (parts...)" when the estimate exceeds the limit
// (core/memory.h). render_scene's grid path and truth_scene call it first.
void check_run_memory(const Scene& scene, RunKind kind);

struct RenderOptions {
  Backend backend = Backend::Cpu;
  uint64_t table_photons = 30000;  // photons per row of tables generated on first use
  float smooth_step = 0;           // "smooth_step": voxels; 0 is the exact traversal (3D grids only)
  bool progress = false;           // progress bars on stderr for CPU work
  // Set: an [axial] scene renders this map instead of building the one its
  // table names (the viewer's painted map, its values as the renderer takes
  // them: after axial.tau_scale and emission_scale); placed by the scene's
  // axial.length_pc, origin and axis (place_axial_map).
  std::shared_ptr<const AxialMap> axial_map;
};

struct RenderOutput {
  Image image;
  ImageMetadata metadata;
  RunReport report;
};

// The fast renderer on a scene: the spectral renderer when the scene has a
// [spectral] table, else its 3D grid, with the light scattered between
// voxels as the scene asks (render.multiple_scattering: the diffuse field, or
// render.levels pyramid levels, or none), or its axial map. Validates the
// scene first. Errors: Error naming the scene file and key, or ParameterError
// for "render.levels" (more levels than the grid allows) and "smooth_step".
RenderOutput render_scene(const Scene& scene, const RenderOptions& options);

// The spectral renderer on a scene with a [spectral] table (docs/spectral.md):
// one plane per band, each the band's filter integrated over wavelength
// (each voxel's scattering table read at a few attenuations, emission as
// lines and continua; no light between voxels). render_scene calls it for such scenes. Errors
// name the scene file and key; a model the spectral library refuses is
// "<scene>: spectral: <reason>".
RenderOutput render_spectral_scene(const Scene& scene, const RenderOptions& options);

// The view-independent part of a grid render (bands, tables, star bakes, the
// diffuse field or the pyramid's coarse levels): a new camera re-renders from
// it with none of that work done again. `scene` must outlive it.
struct PreparedGrid {
  const Scene* scene = nullptr;
  RenderOptions options;
  SceneBands bands;
  BandTables tables;
  BakeResult bake;
  DiffuseField diffuse;  // baked when the scene asks for the diffuse field and something scatters
  PreparedPyramid pyramid;
  RenderInputs inputs;  // everything but the camera and exposure
  RunReport report;     // the work so far
  // What the bakes and the diffuse field were computed from (empty: never
  // reused), compared by the re-preparing overload below.
  std::string bake_key, diffuse_key;
};
PreparedGrid prepare_grid(const Scene& scene, const RenderOptions& options);
// The same after an edit: the star bakes (when the grid and the stars'
// positions are unchanged) and the diffuse field (when, besides, the bands'
// dust, tables and the stars' powers and the field's settings are) move over
// from `previous` instead of being computed again; the report marks them
// reused. Grids are compared by what they were made from (Scene::grid_source).
PreparedGrid prepare_grid(const Scene& scene, const RenderOptions& options, PreparedGrid&& previous);
// The same leaving `previous` unchanged (it may be in use): what is reused is
// copied on the host and shared on the device.
PreparedGrid prepare_grid(const Scene& scene, const RenderOptions& options, const PreparedGrid& previous);
// The scene with its grids halved `levels` times (multires/volume_pyramid.h:
// the dust's mass kept), the diffuse field's cells with them and a quarter of
// its photons per level (twice the photons per cell still): a preview's
// grid, baked on its own. grid_source says so, so its bakes never pass for
// the full grid's. Levels beyond the grid's (the coarsest keeps 2 voxels) are
// not made. Error for an axial scene or negative levels.
Scene coarsened_scene(const Scene& scene, int levels);
// preview: the interactive preview, each voxel's light towards the eye taken
// once per view at its centre (MarchMode::voxel_sources; docs/marcher.md).
RenderOutput render_prepared(const PreparedGrid& prepared, const CameraSettings& camera, bool preview = false);

struct TruthOptions {
  Backend backend = Backend::Cpu;
  int spp = 16;                      // "spp": samples per pixel and band, >= 2
  uint64_t seed = 1;
  int max_orders = 0;                // "max_orders": 0 keeps every order (the truth)
  int majorant_block = 4;            // "majorant_block": voxels per block edge
  bool exact_transmittance = false;  // next-event transmittance by the exact voxel sum
  bool equiangular = false;          // equiangular next-event samples too (MIS)
  int axial_voxels = 256;            // "axial_voxels": an axial map is traced voxelized, this many along its longer side
  std::shared_ptr<const AxialMap> axial_map;  // set: traced instead of the scene's (RenderOptions::axial_map)
  bool progress = false;
};

struct TruthRenderOutput {
  Image image, variance;  // the mean per pixel and band, and the variance of that mean
  ImageMetadata metadata, variance_metadata;
  RunReport report;
};

// The ground-truth path tracer (truth/) on exactly the scene render_scene
// sees: the same bands, stars, emission and camera; drawn stars the same way.
TruthRenderOutput truth_scene(const Scene& scene, const TruthOptions& options);

}  // namespace nebula
