#pragma once
// A linear floating-point image with one plane per band (B, V, R by default).
#include <string>
#include <vector>

namespace nebula {

struct Image {
  int width = 0, height = 0;
  std::vector<std::string> bands;  // plane names, e.g. {"B", "V", "R"}
  std::vector<float> pixels;       // [band][y][x], y = 0 is the top row

  Image() = default;
  Image(int w, int h, std::vector<std::string> band_names)
      : width(w), height(h), bands(std::move(band_names)),
        pixels(size_t(w) * h * bands.size(), 0.0f) {}
  size_t plane_size() const { return size_t(width) * height; }
  float& at(int band, int x, int y) { return pixels[band * plane_size() + size_t(y) * width + x]; }
  float at(int band, int x, int y) const { return pixels[band * plane_size() + size_t(y) * width + x]; }
};

}  // namespace nebula
