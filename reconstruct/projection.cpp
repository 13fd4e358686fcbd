#include "reconstruct/projection.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "axial/axial_renderer.h"
#include "core/error.h"

namespace nebula {

Camera straight_camera(int nx, int nr, float texel) {
  Camera c;
  c.projection = Projection::Orthographic;
  c.width = nx;
  c.height = 2 * nr;
  c.half_width = 0.5f * nx * texel;
  c.half_height = nr * texel;
  // In front of the map's cylinder (radius nr texels), looking along +z.
  c.position = {0.5f * nx * texel, 0.0f, -2.0f * nr * texel};
  c.forward = {0, 0, 1};
  c.right = {1, 0, 0};
  c.up = {0, 1, 0};
  return c;
}

ColumnProjection build_projection(int n, float step_texels, Backend backend) {
  if (n < 1) throw ParameterError("radius", "must be at least 1 texel");
  if (!(step_texels > 0.0f) || !std::isfinite(step_texels))
    throw ParameterError("step_texels", "must be finite and > 0");
  AxialMap diagonal;
  diagonal.nx = diagonal.nr = n;
  diagonal.texel = 1.0f;
  diagonal.origin = {0, 0, 0};
  diagonal.axis = {1, 0, 0};
  diagonal.tau_v.assign(diagonal.count(), 0.0f);
  diagonal.emission.assign(1, std::vector<float>(diagonal.count(), 0.0f));
  for (int i = 0; i < n; ++i) diagonal.emission[0][diagonal.index(i, i)] = 1.0f;
  diagonal.update_skip_structures();

  AxialRenderInputs in;
  in.map = &diagonal;
  AxialRenderBand band;
  band.name = "E";
  band.albedo = 0.0f;
  in.bands.push_back(band);
  in.camera = straight_camera(n, n, 1.0f);
  in.step = step_texels;
  in.skip = AxialSkip::Distance;  // exact: the same image as the naive march
  const auto start = std::chrono::steady_clock::now();
  const Image image = render_axial(in, backend);

  ColumnProjection p;
  p.n = n;
  p.a.assign(size_t(n) * n, 0.0f);
  float peak = 0.0f;
  double worst = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const float above = image.at(0, i, n - 1 - j), below = image.at(0, i, n + j);
      p.a[size_t(i) * n + j] = 0.5f * (above + below);
      peak = std::max(peak, std::max(above, below));
      worst = std::max(worst, double(std::fabs(above - below)));
    }
  p.side_difference = peak > 0 ? worst / peak : 0.0;
  p.row_end.assign(size_t(n), 0);
  p.col_begin.assign(size_t(n), n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (p.at(j, i) != 0.0f) {
        p.row_end[size_t(i)] = std::max(p.row_end[size_t(i)], j + 1);
        p.col_begin[size_t(j)] = std::min(p.col_begin[size_t(j)], i);
      }
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return p;
}

}  // namespace nebula
