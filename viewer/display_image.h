#pragma once
// A rendered frame as the viewer shows it: 8-bit RGBA through the same
// colours and display transform as a PNG file (imageio/image_output.h's
// png_colours, core/display.h, imageio/tone_map.h), with the auto exposure
// chosen from the channels shown, as the PNG writer chooses it.
#include <cstdint>
#include <vector>

#include "core/display.h"
#include "core/image.h"
#include "imageio/image_output.h"

namespace nebula::viewer {

struct Rgba8 {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;  // row 0 at the top, 4 bytes a pixel
  double exposure = 1;          // the exposure used (the auto one when asked)
};

// `metadata` names the bands' pivot wavelengths for bands other than B, V, R (rendered frames carry them).
Rgba8 display_image(const Image& image, double exposure, const DisplaySettings& display, const ImageMetadata& metadata);

}  // namespace nebula::viewer
