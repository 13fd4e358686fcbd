#pragma once
// A rendered frame as the viewer shows it: 8-bit RGBA through the same
// display transform as a PNG file (core/display.h, imageio/tone_map.h): red,
// green, blue from the bands R, V, B (one grey band as grey), with the auto
// exposure chosen from the bands shown, as the PNG writer chooses it.
#include <cstdint>
#include <vector>

#include "core/display.h"
#include "core/image.h"

namespace nebula::viewer {

struct Rgba8 {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;  // row 0 at the top, 4 bytes a pixel
  double exposure = 1;          // the exposure used (the auto one when asked)
};

Rgba8 display_image(const Image& image, double exposure, const DisplaySettings& display);

}  // namespace nebula::viewer
