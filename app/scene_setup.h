#pragma once
// What every command that renders a scene derives from it the same way: the
// camera, each band's extinction ratio and each star's power per band. One
// place, so the fast renderer, the pyramid and the path tracer see one scene.
#include <string>
#include <vector>

#include "illumination/passband.h"
#include "imageio/image_output.h"
#include "raycast/camera.h"
#include "scene/scene.h"

namespace nebula::app {

Camera camera_of(const CameraSpec& spec);

struct SceneBands {
  std::vector<Passband> passbands;              // Bessell, per scene band
  std::vector<float> extinction_ratio;          // A_b / A_V, band-averaged (CCM89 family, the scene's R_V)
  std::vector<std::vector<float>> star_power;   // [star][band]: L_sun inside the band (black body)
};

SceneBands scene_bands(const Scene& scene);

// What every rendered image records of its scene: units, per-band albedo, g
// and extinction ratio, R_V, the camera and the scene file. Callers add their
// own "mode" entry.
ImageMetadata scene_metadata(const Scene& scene, const SceneBands& bands, const Camera& camera);

// Refuses an image format before any work: by extension, and .exr/.png when
// this build has no OpenImageIO.
void check_image_extension(const std::string& option, const std::string& path);

}  // namespace nebula::app
