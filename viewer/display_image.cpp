#include "viewer/display_image.h"

#include <algorithm>
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

}  // namespace nebula::viewer
