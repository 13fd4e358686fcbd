#pragma once
// The column models.
//
// Emission only, the column image is A e (projection.h). With extinction the
// renderer's march attenuates each texel run by what lies before it on the
// ray (the T_in rule, docs/DESIGN.md section 3): the ray at distance b_j
// crosses rings n-1 .. j+1 on its way in, ring j, then rings j+1 .. n-1 on its
// way out, and
//   I_j = sum over those runs s of T_s e_{i_s} c_s,
//   T_s = exp(-ratio sum_{s' < s} tau_{i_s'} c_{s'}),
// with c_s the run's length in texels: A[j, j] for ring j, A[j, i] / 2 on each
// side for the others. The march's split between the two sides differs from
// half by up to a sample, which moves the image by about 1% on the absorbing
// test map: good enough for a Jacobian, not for the residuals (rendered_column).
// With tau = 0 this is A e exactly.
#include <vector>

#include "axial/axial_map.h"
#include "reconstruct/projection.h"

namespace nebula {

// Calls f(ring, length) for the runs of the ray at distance b_j, in the
// order the ray meets them (projection.h's A split into the two sides).
template <class F>
inline void for_each_run(const ColumnProjection& a, int j, F&& f) {
  for (int i = a.n - 1; i > j; --i) f(i, 0.5 * a.at(j, i));
  f(j, double(a.at(j, j)));
  for (int i = j + 1; i < a.n; ++i) f(i, 0.5 * a.at(j, i));
}

// The model image of map column ix in band b (n values).
std::vector<float> emitting_column_image(const ColumnProjection& a, const AxialMap& map, int ix, int band);
std::vector<float> absorbing_column_image(const ColumnProjection& a, const AxialMap& map, int ix, int band,
                                          float ratio);

// The renderer's own image of one map column (n texels; emission per band,
// tau_v; extinction ratio per band), the two sides averaged: [band][j].
// The absorbing fit's residuals and its image error use this; the split
// model above gives only the fit's Jacobian.
std::vector<float> rendered_column(const std::vector<const float*>& emission, const float* tau_v, int n,
                                   const std::vector<float>& ratio, float step_texels);

}  // namespace nebula
