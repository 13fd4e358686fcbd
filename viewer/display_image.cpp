#include "viewer/display_image.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "imageio/tone_map.h"

namespace nebula::viewer {

Rgba8 display_image(const Image& image, double exposure, const DisplaySettings& display, const ImageMetadata& metadata) {
  const std::vector<PngColour> colours = png_colours(image, metadata);
  const size_t plane = image.plane_size();
  const bool grey = image.bands.size() == 1;
  const int channels = grey ? 1 : 3;
  const std::vector<float> shown = shown_channels(image, colours);
  if (display.auto_exposure) exposure = auto_exposure_of(shown, display, exposure);
  Rgba8 out;
  out.width = image.width;
  out.height = image.height;
  out.exposure = exposure;
  out.pixels.assign(plane * 4, 255);
  for (size_t i = 0; i < plane; ++i)
    for (int c = 0; c < 3; ++c)
      out.pixels[i * 4 + size_t(c)] = display_level(shown[size_t(grey ? 0 : c) * plane + i], exposure, display);
  return out;
}

Rgba8 map_plane_image(const AxialMap& map, BrushPlane plane, float* max_value) {
  const std::vector<float>* values =
      plane.is_tau() ? &map.tau_v : size_t(plane.band) < map.emission.size() ? &map.emission[size_t(plane.band)] : nullptr;
  float top = 0;
  if (values)
    for (float v : *values) top = std::max(top, v);
  if (max_value) *max_value = top;
  Rgba8 out;
  out.width = map.nx;
  out.height = map.nr;
  out.pixels.assign(size_t(map.nx) * map.nr * 4, 255);
  for (int y = 0; y < map.nr; ++y)
    for (int x = 0; x < map.nx; ++x) {
      const size_t i = map.index(x, map.nr - 1 - y);
      const float v = values && top > 0 ? (*values)[i] / top : 0.0f;
      const uint8_t level = uint8_t(std::lround(255.0 * std::sqrt(double(std::clamp(v, 0.0f, 1.0f)))));
      uint8_t* p = &out.pixels[(size_t(y) * map.nx + x) * 4];
      p[0] = p[1] = p[2] = level;
      if (plane.is_tau() && level == 0 && !map.empty_at(i)) p[2] = 96;  // emission without dust
    }
  return out;
}

}  // namespace nebula::viewer
