#pragma once
// A [spectral] scene's settings for the spectral library (spectral/): the
// scene's method, basis and depths, its extinction law and R_V. What
// render_spectral_scene (render_scene.h) builds its model with.
#include "illumination/optical_depth_bake.h"
#include "pipeline/render_scene.h"
#include "scene/scene.h"
#include "spectral/spectral_model.h"
#include "spectral/spectral_renderer.h"

namespace nebula {

spectral::SpectralSettings spectral_settings(const Scene& scene);

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

}  // namespace nebula
