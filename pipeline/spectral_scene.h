#pragma once
// A [spectral] scene's settings for the spectral library (spectral/): the
// scene's method, basis and depths, its extinction law and R_V. What
// render_spectral_scene (render_scene.h) builds its model with; and the scene
// prepared once for many views (the viewer's frames).
#include <memory>
#include <optional>
#include <vector>

#include "diffuse/diffuse_field.h"
#include "illumination/optical_depth_bake.h"
#include "pipeline/render_scene.h"
#include "pipeline/scene_bands.h"
#include "raycast/renderer.h"
#include "scene/scene.h"
#include "spectral/spectral_model.h"
#include "spectral/spectral_renderer.h"

namespace nebula {

spectral::SpectralSettings spectral_settings(const Scene& scene);

// The wavelengths (um) named filters span, {lo, hi}: the basis' range a fresh
// model takes where the scene pins none (spectral.range_um). The grey band has
// no wavelengths; none at all: {1e30, 0}.
std::pair<double, double> filters_span_um(const std::vector<std::pair<std::string, Passband>>& filters);

// The light between voxels in two steps: each star's field baked at the
// model's table nodes (does not depend on the view), then, for a camera, the
// fields' per-view pass.
struct SpectralDiffuseFields {
  std::vector<DiffuseField> fields;             // [star]
  std::vector<RenderBand> render_bands;         // [node]
  std::vector<std::vector<double>> node_power;  // [star][node], L_sun um^-1
};

// The light between voxels for the spectral renderer (docs/spectral.md, "Light
// between voxels"): per star, the band renderer's diffuse field of that star
// alone baked at the model's table nodes (render.diffuse_* settings), then its
// per-view pass for `camera`. The bakes go into report.diffuse (their times
// and photons summed; noise and memory the first star's); *view_seconds gets
// the per-view passes' time. The model needs table nodes, the scene a star;
// the stars' depth bakes lend the passes their device copies (a CUDA bake's).
// `tables`: what each table node reads (the dust's one table, or with albedo and
// g varying with wavelength the node's own).
spectral::SpectralDiffuseLight spectral_diffuse_light(const Scene& scene, const spectral::SpectralModel& model,
                                                      const std::vector<const ScatteringTable*>& tables,
                                                      BakeResult& bake,
                                                      const Camera& camera, const RenderOptions& o,
                                                      RunReport& report, double* view_seconds);

SpectralDiffuseFields bake_spectral_diffuse(const Scene& scene, const spectral::SpectralModel& model,
                                            const std::vector<const ScatteringTable*>& tables, BakeResult& bake,
                                            const RenderOptions& o, RunReport& report);
spectral::SpectralDiffuseLight spectral_diffuse_view(const Scene& scene, const SpectralDiffuseFields& fields,
                                                     BakeResult& bake, const Camera& camera, Backend backend,
                                                     double* view_seconds);

// A [spectral] scene made ready for many views: its model (filters, basis,
// star and depth tables), the voxels' tables, the stars' depth bakes and the
// light between voxels' fields. A view (render_prepared_spectral) then costs
// the fields' per-view pass, the march and the resolve: what `nebula render`
// does after its preparation, so its image equals render_spectral_scene's
// with that camera. The scene must outlive it.
struct PreparedSpectral {
  const Scene* scene = nullptr;
  RenderOptions options;
  SceneBands bands;
  RunReport report;  // the preparation's (tables, bakes, model); each view adds its own
  spectral::SpectralModel model;
  std::shared_ptr<const ScatteringTable> table;                    // the dust's, or null
  std::vector<std::shared_ptr<const ScatteringTable>> node_tables;  // albedo and g varying with wavelength
  std::shared_ptr<BakeResult> bake;  // shared, not const: the views' CUDA passes keep its device copies
  std::shared_ptr<const SpectralDiffuseFields> diffuse;  // or null
  int table_nodes = 0, emission_components = 0;
  bool tables = false;
  // What each part depends on, to be kept by a later preparation (empty for
  // a scene built in code: nothing is kept). The fields: the scene's resolved
  // text without its bands, filters, view, basis range and per-band dust,
  // with the options; the model: its [spectral], [dust] and [[stars]] tables;
  // the depth bakes: star_bake_key.
  std::string depends_on, model_key, bake_key;
};
// With `previous` (an earlier preparation, its scene still alive), what the
// changes left unchanged is taken over instead of made again, as the band
// renderer's prepare_grid does after an edit:
// - the depth bakes, when the grid and the stars' positions are the same
//   (report.bake.reused);
// - the model (basis and star tables), when the [spectral] settings, the
//   dust's law and R_V and the stars are the same and so is the basis'
//   wavelength range (spectral.range_um, or the bands' span); new filters
//   then go onto it (spectral::set_filters: the projection, light_density,
//   voxel_light and preintegrated methods; the others build anew)
//   (report.spectral->basis_kept);
// - the light between voxels' fields, when besides the bakes nothing else
//   changed but the filters and the view: the same table, albedo, g and
//   nodes (report.diffuse.reused).
// The image is a fresh preparation's, bit for bit.
std::shared_ptr<const PreparedSpectral> prepare_spectral(const Scene& scene, const RenderOptions& options,
                                                         const PreparedSpectral* previous = nullptr);
RenderOutput render_prepared_spectral(const PreparedSpectral& prepared, const CameraSettings& camera);

}  // namespace nebula
