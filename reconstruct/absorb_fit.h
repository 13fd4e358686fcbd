#pragma once
// The absorbing fit (method absorb): per column, one emission shape e(r)
// with a colour per band (band b emits s_b e(r)) and one tau_v(r) shared by
// the bands (tau_b = ratio_b tau_v), all >= 0, fitted to
// the image through the absorbing column model (column_model.h) by a bounded
// nonlinear least-squares fit (Ceres, Levenberg-Marquardt; residuals from the
// renderer's own image of the column, the Jacobian from the split model) started from the NNLS emission and tau_v = 0, with the same
// Tikhonov smoothing as NNLS on e and tau_v. One colour per column is what
// makes tau_v visible: the bands' different extinction of the same emission.
// With a colour per texel there are more unknowns than pixels (any image is
// fitted by emission alone), so that model cannot be identified. Its own library target
// (nebula_reconstruct_absorb) so that Ceres stays out of the GPU tests.
#include "reconstruct/projection.h"
#include "reconstruct/reconstruct.h"

namespace nebula {

struct AbsorbTotals {
  long long iterations = 0;
  int not_converged = 0;
};

// Refits every column of `map` (emission in, e.g. from NNLS; tau_v out).
AbsorbTotals fit_absorbing_map(const ColumnProjection& a, const StraightImage& image, const std::vector<float>& ratio,
                               double smoothness, float step_texels, AxialMap& map);

// NNLS, then the absorbing fit; any method in `s` runs as absorb.
AxialMap reconstruct_absorbing_map(const StraightImage& image, const ReconstructSettings& s,
                                   ReconstructReport* report = nullptr);

// Any method: reconstruct_axial_map, or reconstruct_absorbing_map for absorb.
AxialMap reconstruct_any(const StraightImage& image, const ReconstructSettings& s, ReconstructReport* report = nullptr);

}  // namespace nebula
