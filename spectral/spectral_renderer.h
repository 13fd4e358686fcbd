#pragma once
// Renders a voxel grid through any number of filters with the spectral
// marcher (spectral/spectral_march.h): one function for the CPU (TBB) and
// CUDA. The march writes each ray's accumulators; resolve_filters turns them
// into one plane per filter (a filter change re-runs only the resolve).
#include <vector>

#include "core/backend.h"
#include "core/camera.h"
#include "core/grid.h"
#include "core/image.h"
#include "spectral/spectral_model.h"
#include "tables/scattering_table.h"

namespace nebula::spectral {

struct SpectralLight {
  Vec3 position;
  double luminosity_lsun = 1;
  const std::vector<float>* depth_v = nullptr;  // baked V-band depth per voxel (illumination/optical_depth_bake.h)
};

// The voxel-light method's per-view buffers (4 F N floats and a star mask per
// voxel): a caller rendering several frames passes one so that they are
// allocated (and their pages first touched) once, not per frame.
struct VoxelLightWorkspace {
  std::vector<float> light;
  std::vector<unsigned> near;
};

// An emission component's weight per voxel (SpectralEmission: j = w phi): the
// grid (the density's shape) times scale, or the voxel's tau_V times scale.
struct SpectralEmissionWeight {
  const std::vector<float>* grid = nullptr;
  float scale = 1;
};

// Light scattered between voxels (docs/spectral.md, "Light between voxels"):
// the band renderer's diffuse field baked star by star at the model's table
// nodes (one band per node, kappa_m, the star's spectral power at a wavelength
// of that kappa) and its per-view pass for this camera (raycast/renderer.h,
// diffuse_light_arrays).
struct SpectralDiffuseLight {
  std::vector<std::vector<std::vector<float>>> light;  // [star][node][voxel]: towards the eye, per unit chord / l
  std::vector<std::vector<float>> peak;                // [node][voxel]: the forward peak (the same for every star)
  // The same arrays on the device, from a CUDA per-view pass ([star][node] and
  // [node], each of the grid's voxels; the host arrays then empty): the CUDA
  // renderer reads them where they are, the CPU's downloads them.
  std::vector<std::vector<DeviceMirror>> device_light;
  std::vector<DeviceMirror> device_peak;
  std::vector<std::vector<double>> node_power;         // [star][node]: its pass' power, L_sun um^-1
  bool on_device() const { return light.empty() && !device_light.empty(); }
};

struct SpectralRenderInputs {
  const DensityGrid* density = nullptr;
  const SpectralModel* model = nullptr;  // built for these lights, in this order
  std::vector<SpectralLight> lights;
  float albedo = 0.6f, g = 0.6f;
  // The voxels' scattering table for (albedo, g), read at the model's
  // table_nodes attenuations (docs/spectral.md, "Tables"); null, or a model
  // with table_nodes 0: the thin-voxel limit P = tau_sct p_HG.
  const ScatteringTable* table = nullptr;
  // Albedo and g varying with wavelength (a model with curves): one table per
  // table node, for that node's albedo and g (SpectralModel::node_albedo,
  // node_g; `table` is then unused); none: the thin-voxel limit at each node.
  // albedo and g above are the reference the pair weights are made with.
  std::vector<const ScatteringTable*> node_tables;
  std::vector<SpectralEmissionWeight> emission;  // one per model->emission component
  // With a table and table nodes (the model's); null: none.
  const SpectralDiffuseLight* diffuse = nullptr;
  Camera camera;
  bool star_pixels = true;  // the pixels at each star's image with many rays each (illumination/star_pixels.h)
  VoxelLightWorkspace* workspace = nullptr;  // VoxelLight on the CPU: reused buffers (optional)
};

// The accumulator image (model->planes(): the stars', then the emission's); `seconds` the march with
// its per-view work (the voxel-light pre-pass, the light between voxels' terms; CUDA events on the GPU). Throws Error on inconsistent inputs (a table for
// another albedo or g than the dust's among them).
Image render_spectral(const SpectralRenderInputs& in, Backend backend, double* seconds = nullptr);
Image render_spectral_cpu(const SpectralRenderInputs& in, double* seconds);
Image render_spectral_cuda(const SpectralRenderInputs& in, double* seconds);

// One plane per filter (the model's names), times the exposure.
Image resolve_filters(const Image& accumulators, const SpectralModel& model, float exposure = 1.0f);

// The per-voxel terms of the light between voxels (SpectralSceneView::diffuse
// and eye_tau: diffuse_voxel_terms, diffuse_eye_depth) on the host (the CPU
// renderer's; the CUDA renderer runs the same functions in a kernel); empty
// without it.
struct DiffuseTerms {
  std::vector<float> terms, eye_tau;
};
DiffuseTerms diffuse_terms(const SpectralRenderInputs& in, const SpectralSceneView& view);

// The scene view's emission weights (`grids[c]`: component c's grid where it
// lives, host or device, or null for tau_V).
void set_emission(SpectralSceneView& view, const SpectralRenderInputs& in, const std::vector<const float*>& grids);

// The scene view's table fields for these inputs (both backends; `P` and `C`
// are the table's values and cumulative rows (tables/table_lookup.h) where they
// live, host or device; with varying albedo and g, node_P and node_C the node
// tables', where they live).
void set_table(SpectralSceneView& view, const SpectralRenderInputs& in, const float* P, const float* C,
               const std::vector<const float*>& node_P = {}, const std::vector<const float*>& node_C = {});

// SpectralSceneView::node_table for these inputs and the view's nodes (set_table
// first), built on the host from the tables: every node's value at rows of
// V-band depth and the table's bin centres; empty where the nodes read their own
// lookups (the thin limit, a node without a table, a zero albedo).
struct NodeTable {
  std::vector<float> values;  // [row][bin][4]
  int rows = 0;
  float step = 1;
};
NodeTable node_table(const SpectralRenderInputs& in, const SpectralSceneView& view);
// Points the view at a node table whose values lie at `values` (host or device).
void use_node_table(SpectralSceneView& view, const NodeTable& nodes, const float* values);

}  // namespace nebula::spectral
