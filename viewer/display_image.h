#pragma once
// A rendered frame as the viewer shows it: 8-bit RGBA through the same
// colours and display transform as a PNG file (imageio/image_output.h's
// png_colours, core/display.h, imageio/tone_map.h), with the auto exposure
// chosen from the channels shown, as the PNG writer chooses it.
#include <cstdint>
#include <vector>

#include "axial/axial_brush.h"
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

// One plane of an axial map as the paint panel shows it: x to the right, the
// axis (r = 0) at the bottom row; grey levels sqrt(v / max) of the plane's
// largest value (returned in *max_value; all black for an empty plane, or an
// emission plane the map lacks). Painted texels with no dust but emission
// are tinted blue on the tau_v plane so that emission alone stays visible.
Rgba8 map_plane_image(const AxialMap& map, BrushPlane plane, float* max_value = nullptr);

}  // namespace nebula::viewer
