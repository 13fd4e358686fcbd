#pragma once
// A [spectral] scene's settings for the spectral library (spectral/): the
// scene's method, basis and depths, its extinction law and R_V. What
// render_spectral_scene (render_scene.h) builds its model with.
#include "scene/scene.h"
#include "spectral/spectral_model.h"

namespace nebula {

spectral::SpectralSettings spectral_settings(const Scene& scene);

}  // namespace nebula
