#pragma once
// The forward model of the reconstruction is the axial renderer itself
// (axial/axial_renderer.h). Seen perpendicular to its axis (the thesis'
// inclination 0) an emission-only map renders column by column: the pixel at
// distance b from the axis in image column ix sums texels of map column ix
// only, each weighted by the length of the ray inside it. So image column =
// A e, the same matrix A for every column. We get A by rendering, with the
// renderer's own march, the "diagonal" map of nr x nr texels whose column i
// emits 1 in texel i only: pixel (i, j) of that render is A[j, i].
#include <vector>

#include "core/backend.h"
#include "core/camera.h"
#include "reconstruct/powell_column.h"

namespace nebula {

// The map frame the reconstruction uses: origin 0, axis +x, texels of edge
// `texel`. The straightened image is nx columns by 2 nr rows, one pixel per
// texel, the axis between rows nr - 1 and nr (rows 0 .. nr - 1 above it, the
// outermost first). This camera renders a map of that frame as that image:
// orthographic, looking along +z, perpendicular to the axis.
Camera straight_camera(int nx, int nr, float texel);

struct ColumnProjection {
  int n = 0;                   // texels per map column = pixels per side of the axis
  std::vector<float> a;        // column-major, a[i * n + j] = A[j, i], the two sides averaged
  std::vector<int> row_end;    // A[j, i] = 0 for j >= row_end[i]
  std::vector<int> col_begin;  // A[j, i] = 0 for i < col_begin[j]
  double side_difference = 0;  // max |A_above - A_below| / max A: the two sides' rendering differences
  double seconds = 0;          // the render of the diagonal map

  ColumnSystem view() const { return {n, a.data(), row_end.data(), col_begin.data()}; }
  float at(int j, int i) const { return a[size_t(i) * n + j]; }
};

// A for columns of n texels, marched with step `step_texels` (as the scene's
// axial.step_texels), rendered on `backend`.
ColumnProjection build_projection(int n, float step_texels, Backend backend);

}  // namespace nebula
