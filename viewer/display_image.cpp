#include "viewer/display_image.h"

#include <algorithm>
#include <string>

#include "imageio/tone_map.h"

namespace nebula::viewer {

Rgba8 display_image(const Image& image, double exposure, const DisplaySettings& display) {
  std::vector<int> source;
  if (image.bands.size() == 1) {
    source = {0, 0, 0};
  } else {
    for (const char* band : {"R", "V", "B"}) {
      const auto at = std::find(image.bands.begin(), image.bands.end(), band);
      source.push_back(at == image.bands.end() ? -1 : int(at - image.bands.begin()));
    }
  }
  const size_t plane = image.plane_size();
  if (display.auto_exposure) {
    // The bands shown, once each (the PNG writer's choice: core/display.h).
    std::vector<float> shown;
    std::vector<int> distinct;
    for (int s : source)
      if (s >= 0 && std::find(distinct.begin(), distinct.end(), s) == distinct.end()) distinct.push_back(s);
    for (int s : distinct)
      shown.insert(shown.end(), image.pixels.begin() + std::ptrdiff_t(size_t(s) * plane),
                   image.pixels.begin() + std::ptrdiff_t(size_t(s + 1) * plane));
    exposure = auto_exposure_of(shown, display, exposure);
  }
  Rgba8 out;
  out.width = image.width;
  out.height = image.height;
  out.exposure = exposure;
  out.pixels.assign(plane * 4, 255);
  for (size_t i = 0; i < plane; ++i)
    for (int c = 0; c < 3; ++c)
      out.pixels[i * 4 + size_t(c)] =
          source[size_t(c)] < 0 ? 0 : display_level(image.pixels[size_t(source[size_t(c)]) * plane + i], exposure, display);
  return out;
}

}  // namespace nebula::viewer
