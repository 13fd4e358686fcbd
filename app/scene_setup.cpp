#include "app/scene_setup.h"

#include "core/error.h"
#include "illumination/data_dir.h"
#include "illumination/extinction.h"
#include "illumination/star.h"
#include "imageio/image_output.h"

namespace nebula::app {

Camera camera_of(const CameraSpec& c) {
  CameraSettings s;
  s.projection = c.kind == CameraKind::Perspective    ? Projection::Perspective
                 : c.kind == CameraKind::Orthographic ? Projection::Orthographic
                                                      : Projection::Fisheye;
  s.position = c.position;
  s.look_at = c.look_at;
  s.up = c.up;
  s.fov_deg = c.fov_deg;
  s.ortho_width = c.ortho_width;
  s.width = c.width;
  s.height = c.height;
  return make_camera(s);
}

SceneBands scene_bands(const Scene& scene) {
  const std::string data = default_data_dir();
  SceneBands out;
  const size_t n_bands = scene.bands.size();
  for (const std::string& b : scene.bands) out.passbands.push_back(load_bessell(data, b.at(0)));
  const double v = band_extinction_ratio(load_bessell(data, 'V'), scene.dust.R_V, scene.dust.law);
  for (size_t b = 0; b < n_bands; ++b)
    out.extinction_ratio.push_back(
        static_cast<float>(band_extinction_ratio(out.passbands[b], scene.dust.R_V, scene.dust.law) / v));
  for (const SceneStar& star : scene.stars) {
    std::vector<float> p(n_bands);
    for (size_t b = 0; b < n_bands; ++b)
      p[b] = static_cast<float>(star.luminosity_lsun * band_fraction(star.temperature_K, out.passbands[b]));
    out.star_power.push_back(p);
  }
  return out;
}

ImageMetadata scene_metadata(const Scene& scene, const SceneBands& bands, const Camera& camera) {
  ImageMetadata meta;
  meta.units = "L_sun pc^-2 sr^-1 x exposure";
  meta.exposure = 1.0;  // the camera exposure is already in the pixels
  for (size_t b = 0; b < scene.bands.size(); ++b) {
    meta.entries.push_back({"albedo_" + scene.bands[b], to_text(scene.dust.albedo[b])});
    meta.entries.push_back({"g_" + scene.bands[b], to_text(scene.dust.g[b])});
    meta.entries.push_back({"ext_" + scene.bands[b], to_text(bands.extinction_ratio[b])});
  }
  meta.entries.push_back({"R_V", to_text(scene.dust.R_V)});
  meta.entries.push_back({"camera", std::string(to_string(scene.camera.kind)) + " " + std::to_string(camera.width) +
                                        "x" + std::to_string(camera.height)});
  meta.entries.push_back({"scene", scene.path});
  return meta;
}

void check_image_extension(const std::string& option, const std::string& out) {
  const auto dot = out.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : out.substr(dot);
  if (ext != ".h5" && ext != ".fits" && ext != ".fit" && ext != ".exr" && ext != ".png")
    throw Error(option + ": " + out + ": unknown image format; use .exr, .fits, .png or .h5");
  if ((ext == ".exr" || ext == ".png") && !openimageio_available())
    throw Error(option + ": " + out + ": " + ext + " needs OpenImageIO, which this build lacks; use .h5 or .fits");
}

}  // namespace nebula::app
