#include "reconstruct/column_model.h"

#include <cmath>

#include "axial/axial_renderer.h"

namespace nebula {

std::vector<float> emitting_column_image(const ColumnProjection& a, const AxialMap& map, int ix, int band) {
  std::vector<float> out(size_t(a.n), 0.0f);
  const std::vector<float>& e = map.emission[size_t(band)];
  for (int j = 0; j < a.n; ++j) {
    double v = 0;
    for (int i = a.col_begin[size_t(j)]; i < a.n; ++i) v += double(a.at(j, i)) * e[map.index(ix, i)];
    out[size_t(j)] = float(v);
  }
  return out;
}

std::vector<float> absorbing_column_image(const ColumnProjection& a, const AxialMap& map, int ix, int band,
                                          float ratio) {
  std::vector<float> out(size_t(a.n), 0.0f);
  const std::vector<float>& e = map.emission[size_t(band)];
  for (int j = 0; j < a.n; ++j) {
    double t = 1.0, sum = 0.0;
    for_each_run(a, j, [&](int i, double c) {
      sum += t * e[map.index(ix, i)] * c;
      t *= std::exp(-double(ratio) * map.tau_v[map.index(ix, i)] * c);
    });
    out[size_t(j)] = float(sum);
  }
  return out;
}

std::vector<float> rendered_column(const std::vector<const float*>& emission, const float* tau_v, int n,
                                   const std::vector<float>& ratio, float step_texels) {
  AxialMap m;
  m.nx = 1;
  m.nr = n;
  m.texel = 1.0f;
  m.origin = {0, 0, 0};
  m.axis = {1, 0, 0};
  m.tau_v.assign(tau_v, tau_v + n);
  for (const float* e : emission) m.emission.emplace_back(e, e + n);
  m.update_skip_structures();
  AxialRenderInputs in;
  in.map = &m;
  for (size_t b = 0; b < emission.size(); ++b) {
    AxialRenderBand band;
    band.name = "b" + std::to_string(b);
    band.extinction_ratio = ratio[b];
    band.albedo = 0.0f;
    in.bands.push_back(band);
  }
  in.camera = straight_camera(1, n, 1.0f);
  in.step = step_texels;
  const Image image = render_axial_cpu(in, nullptr);
  std::vector<float> out(emission.size() * size_t(n));
  for (size_t b = 0; b < emission.size(); ++b)
    for (int j = 0; j < n; ++j)
      out[b * n + j] = 0.5f * (image.at(int(b), 0, n - 1 - j) + image.at(int(b), 0, n + j));
  return out;
}

}  // namespace nebula
