#include "multires/image_pyramid.h"

#include <tbb/parallel_for.h>

#include <string>

#include "core/error.h"
#include "multires/pyramid_pixels.h"

namespace nebula {
namespace {

void check_one_level_coarser(const Image& coarse, int width, int height, const char* what) {
  if (coarse.width != coarser_size(width) || coarse.height != coarser_size(height))
    throw Error(std::string(what) + ": image " + std::to_string(coarse.width) + "x" + std::to_string(coarse.height) +
                " is not one level coarser than " + std::to_string(width) + "x" + std::to_string(height));
}

// Runs f(band, y) for every row of every band of `out`, in parallel.
template <class F>
void for_rows(const Image& out, F&& f) {
  const int rows = out.height * int(out.bands.size());
  tbb::parallel_for(0, rows, [&](int row) { f(row / out.height, row % out.height); });
}

const float* plane(const Image& im, int band) { return im.pixels.data() + band * im.plane_size(); }
float* plane(Image& im, int band) { return im.pixels.data() + band * im.plane_size(); }

}  // namespace

int coarser_size(int n) { return (n + 1) / 2; }

Image downsample_2x(const Image& fine) {
  Image out(coarser_size(fine.width), coarser_size(fine.height), fine.bands);
  for_rows(out, [&](int b, int y) {
    for (int x = 0; x < out.width; ++x) out.at(b, x, y) = box_down(plane(fine, b), fine.width, fine.height, x, y);
  });
  return out;
}

Image upsample_2x(const Image& coarse, int width, int height) {
  check_one_level_coarser(coarse, width, height, "upsample");
  Image out(width, height, coarse.bands);
  for_rows(out, [&](int b, int y) {
    for (int x = 0; x < width; ++x) out.at(b, x, y) = bilinear_up(plane(coarse, b), coarse.width, coarse.height, x, y);
  });
  return out;
}

Image clipped_difference(const Image& coarse, const Image& finer) {
  check_one_level_coarser(coarse, finer.width, finer.height, "pyramid difference");
  if (coarse.bands != finer.bands) throw Error("pyramid difference: the levels have different bands");
  Image out(coarse.width, coarse.height, coarse.bands);
  for_rows(out, [&](int b, int y) {
    for (int x = 0; x < out.width; ++x)
      out.at(b, x, y) = pyramid_sum(plane(coarse, b), plane(finer, b), finer.width, finer.height, nullptr, 0, 0,
                                    coarse.width, x, y);
  });
  return out;
}

Image combine_pyramid(const std::vector<Image>& levels, std::vector<Image>* differences) {
  if (levels.empty()) throw Error("pyramid: no images to combine");
  const int n = int(levels.size()) - 1;
  for (int j = 1; j <= n; ++j) {
    check_one_level_coarser(levels[j], levels[j - 1].width, levels[j - 1].height, "pyramid");
    if (levels[j].bands != levels[0].bands) throw Error("pyramid: the levels have different bands");
  }
  if (differences) {
    differences->assign(levels.size(), Image());
    for (int j = 1; j <= n; ++j) (*differences)[j] = clipped_difference(levels[j], levels[j - 1]);
  }
  Image sum;  // S_j at level j's size
  for (int j = n; j >= 1; --j) {
    const Image& level = levels[j];
    const Image& finer = levels[j - 1];
    Image s(level.width, level.height, level.bands);
    for_rows(s, [&](int b, int y) {
      for (int x = 0; x < s.width; ++x)
        s.at(b, x, y) = pyramid_sum(plane(level, b), plane(finer, b), finer.width, finer.height,
                                    j < n ? plane(sum, b) : nullptr, sum.width, sum.height, level.width, x, y);
    });
    sum = std::move(s);
  }
  Image out = levels[0];
  if (n >= 1)
    for_rows(out, [&](int b, int y) {
      for (int x = 0; x < out.width; ++x) out.at(b, x, y) += bilinear_up(plane(sum, b), sum.width, sum.height, x, y);
    });
  return out;
}

}  // namespace nebula
