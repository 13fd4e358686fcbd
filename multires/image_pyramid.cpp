#include "multires/image_pyramid.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace nebula {
namespace {

void check_levels_match(const Image& coarse, const Image& finer, const char* what) {
  if (coarse.bands != finer.bands || coarse.width != coarser_size(finer.width) ||
      coarse.height != coarser_size(finer.height))
    throw Error(std::string(what) + ": image " + std::to_string(coarse.width) + "x" + std::to_string(coarse.height) +
                " is not one level coarser than " + std::to_string(finer.width) + "x" + std::to_string(finer.height) +
                " with the same bands");
}

}  // namespace

int coarser_size(int n) { return (n + 1) / 2; }

Image downsample_2x(const Image& fine) {
  Image out(coarser_size(fine.width), coarser_size(fine.height), fine.bands);
  for (size_t b = 0; b < fine.bands.size(); ++b)
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x) {
        double sum = 0;
        int n = 0;
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const int fx = 2 * x + dx, fy = 2 * y + dy;
            if (fx < fine.width && fy < fine.height) {
              sum += fine.at(int(b), fx, fy);
              ++n;
            }
          }
        out.at(int(b), x, y) = static_cast<float>(sum / n);
      }
  return out;
}

Image upsample_2x(const Image& coarse, int width, int height) {
  if (coarse.width != coarser_size(width) || coarse.height != coarser_size(height))
    throw Error("upsample: " + std::to_string(coarse.width) + "x" + std::to_string(coarse.height) +
                " is not one level coarser than " + std::to_string(width) + "x" + std::to_string(height));
  Image out(width, height, coarse.bands);
  // Fine pixel centre x + 1/2 lies at coarse pixel coordinate (x + 1/2) / 2 - 1/2.
  auto axis = [](int i, int n_coarse, int& i0, int& i1, float& w) {
    const float c = std::clamp((i + 0.5f) * 0.5f - 0.5f, 0.0f, float(n_coarse - 1));
    i0 = static_cast<int>(c);
    i1 = std::min(i0 + 1, n_coarse - 1);
    w = c - i0;
  };
  for (size_t b = 0; b < coarse.bands.size(); ++b)
    for (int y = 0; y < height; ++y) {
      int y0, y1;
      float wy;
      axis(y, coarse.height, y0, y1, wy);
      for (int x = 0; x < width; ++x) {
        int x0, x1;
        float wx;
        axis(x, coarse.width, x0, x1, wx);
        const int band = int(b);
        out.at(band, x, y) = (1 - wy) * ((1 - wx) * coarse.at(band, x0, y0) + wx * coarse.at(band, x1, y0)) +
                             wy * ((1 - wx) * coarse.at(band, x0, y1) + wx * coarse.at(band, x1, y1));
      }
    }
  return out;
}

Image clipped_difference(const Image& coarse, const Image& finer) {
  check_levels_match(coarse, finer, "pyramid difference");
  Image out = downsample_2x(finer);
  for (size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = std::max(coarse.pixels[i] - out.pixels[i], 0.0f);
  return out;
}

Image combine_pyramid(const std::vector<Image>& levels, std::vector<Image>* differences) {
  if (levels.empty()) throw Error("pyramid: no images to combine");
  const int n = int(levels.size()) - 1;
  if (differences) differences->assign(levels.size(), Image());
  Image sum;  // at level j's size: dI_j + up(sum of coarser)
  for (int j = n; j >= 1; --j) {
    Image d = clipped_difference(levels[j], levels[j - 1]);
    if (differences) (*differences)[j] = d;
    if (j < n) {
      const Image up = upsample_2x(sum, d.width, d.height);
      for (size_t i = 0; i < d.pixels.size(); ++i) d.pixels[i] += up.pixels[i];
    }
    sum = std::move(d);
  }
  Image out = levels[0];
  if (n >= 1) {
    const Image up = upsample_2x(sum, out.width, out.height);
    for (size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] += up.pixels[i];
  }
  return out;
}

}  // namespace nebula
