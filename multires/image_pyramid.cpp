#include "multires/image_pyramid.h"

#include <tbb/parallel_for.h>

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
  const int n_bands = int(fine.bands.size());
  tbb::parallel_for(0, out.height * n_bands, [&](int row) {
    const int b = row / out.height, y = row % out.height;
    const bool two_rows = 2 * y + 1 < fine.height;
    const float* r0 = &fine.pixels[b * fine.plane_size() + size_t(2 * y) * fine.width];
    const float* r1 = two_rows ? r0 + fine.width : r0;
    float* o = &out.pixels[b * out.plane_size() + size_t(y) * out.width];
    for (int x = 0; x < out.width; ++x) {
      const bool two_columns = 2 * x + 1 < fine.width;
      const int x1 = two_columns ? 2 * x + 1 : 2 * x;
      const float sum = r0[2 * x] + r0[x1] + r1[2 * x] + r1[x1];  // edge pixels counted twice or four times
      o[x] = sum * 0.25f;
    }
  });
  return out;
}

namespace {

// target += bilinear up-sampling of `coarse` (one level coarser), row by row.
void add_upsampled(const Image& coarse, Image& target) {
  const int width = target.width, height = target.height;
  if (coarse.width != coarser_size(width) || coarse.height != coarser_size(height) || coarse.bands != target.bands)
    throw Error("upsample: " + std::to_string(coarse.width) + "x" + std::to_string(coarse.height) +
                " is not one level coarser than " + std::to_string(width) + "x" + std::to_string(height));
  // Fine pixel centre i + 1/2 lies at coarse pixel coordinate (i + 1/2) / 2 - 1/2.
  auto axis = [](int i, int n_coarse, int& i0, int& i1, float& w) {
    const float c = std::clamp((i + 0.5f) * 0.5f - 0.5f, 0.0f, float(n_coarse - 1));
    i0 = static_cast<int>(c);
    i1 = std::min(i0 + 1, n_coarse - 1);
    w = c - i0;
  };
  std::vector<int> x0(width), x1(width);
  std::vector<float> wx(width);
  for (int x = 0; x < width; ++x) axis(x, coarse.width, x0[x], x1[x], wx[x]);
  const size_t n_bands = coarse.bands.size();
  tbb::parallel_for(0, height * int(n_bands), [&](int row) {
    const int b = row / height, y = row % height;
    int y0, y1;
    float wy;
    axis(y, coarse.height, y0, y1, wy);
    const float* c0 = &coarse.pixels[b * coarse.plane_size() + size_t(y0) * coarse.width];
    const float* c1 = &coarse.pixels[b * coarse.plane_size() + size_t(y1) * coarse.width];
    float* t = &target.pixels[b * target.plane_size() + size_t(y) * width];
    for (int x = 0; x < width; ++x)
      t[x] += (1 - wy) * ((1 - wx[x]) * c0[x0[x]] + wx[x] * c0[x1[x]]) + wy * ((1 - wx[x]) * c1[x0[x]] + wx[x] * c1[x1[x]]);
  });
}

}  // namespace

Image upsample_2x(const Image& coarse, int width, int height) {
  Image out(width, height, coarse.bands);
  add_upsampled(coarse, out);
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
    if (j < n) add_upsampled(sum, d);
    sum = std::move(d);
  }
  Image out = levels[0];
  if (n >= 1) add_upsampled(sum, out);
  return out;
}

}  // namespace nebula
