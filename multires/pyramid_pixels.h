#pragma once
// Per-pixel steps of the image pyramid, written once for the host loops
// (image_pyramid.cpp) and the CUDA kernels (pyramid_render_cuda.cu). A plane
// is one band of an image, row-major, y = 0 the top row.
#include "core/hd.h"

namespace nebula {

// Mean of the 2x2 block of `fine` (w x h) under coarse pixel (x, y); at an odd
// edge the missing row or column repeats the last one (the mean of the pixels
// that exist).
NEBULA_HD float box_down(const float* fine, int w, int h, int x, int y) {
  const int x0 = 2 * x, y0 = 2 * y;
  const int x1 = x0 + 1 < w ? x0 + 1 : x0, y1 = y0 + 1 < h ? y0 + 1 : y0;
  const float* r0 = fine + size_t(y0) * w;
  const float* r1 = fine + size_t(y1) * w;
  return 0.25f * ((r0[x0] + r0[x1]) + (r1[x0] + r1[x1]));
}

// Bilinear value of `coarse` (cw x ch, one level coarser) at the centre of
// fine pixel (x, y): fine centre i + 1/2 lies at coarse coordinate
// (i + 1/2) / 2 - 1/2; clamped at the edges.
NEBULA_HD float bilinear_up(const float* coarse, int cw, int ch, int x, int y) {
  float cx = (x + 0.5f) * 0.5f - 0.5f, cy = (y + 0.5f) * 0.5f - 0.5f;
  cx = cx < 0.0f ? 0.0f : (cx > cw - 1 ? float(cw - 1) : cx);
  cy = cy < 0.0f ? 0.0f : (cy > ch - 1 ? float(ch - 1) : cy);
  const int x0 = static_cast<int>(cx), y0 = static_cast<int>(cy);
  const int x1 = x0 + 1 < cw ? x0 + 1 : x0, y1 = y0 + 1 < ch ? y0 + 1 : y0;
  const float wx = cx - x0, wy = cy - y0;
  const float* r0 = coarse + size_t(y0) * cw;
  const float* r1 = coarse + size_t(y1) * cw;
  return (1 - wy) * ((1 - wx) * r0[x0] + wx * r0[x1]) + wy * ((1 - wx) * r1[x0] + wx * r1[x1]);
}

// Level j's clipped difference at (x, y) plus the up-sampled sum of the
// coarser levels (`coarser` null at the coarsest level): S_j of the
// combination I_0 + up(S_1), S_j = max(I_j - down(I_{j-1}), 0) + up(S_{j+1}).
NEBULA_HD float pyramid_sum(const float* level, const float* finer, int w_finer, int h_finer, const float* coarser,
                            int w_coarser, int h_coarser, int w, int x, int y) {
  const float d = level[size_t(y) * w + x] - box_down(finer, w_finer, h_finer, x, y);
  const float clipped = d > 0.0f ? d : 0.0f;
  return coarser ? clipped + bilinear_up(coarser, w_coarser, h_coarser, x, y) : clipped;
}

}  // namespace nebula
