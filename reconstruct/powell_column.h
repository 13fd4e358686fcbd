#pragma once
// The thesis' reconstruction (Khalass 2021, section 3.3): analysis by
// synthesis with Powell's method, one image column and one colour channel at a
// time, emission only, non-negative, coarse to fine. Written once for host and
// device: a "team" runs it, one thread on the CPU (SerialTeam) or one CUDA
// block on the GPU (reconstruct_cuda.cu), so both backends run this function.
//
// The column problem: find e >= 0 (the map's column, nr texels) minimising
// f(e) = sum_j (sum_i A[j, i] e_i - p_j)^2, where p is the image column (the
// two sides of the axis averaged) and A the renderer's response of pixel j to
// texel i (reconstruct/projection.h). At inclination 0 with emission only the
// rendered column is exactly A e, so the synthesis of a trial map is A e, kept
// as the residual r = A e - p and updated along each search direction.
//
// Powell's method here: each sweep runs one line minimisation along every
// coordinate direction (a group of texels at the coarse levels), then one
// along the sweep's net displacement (Powell's extrapolated direction); the
// direction set is reset to the coordinates every sweep, so a block keeps
// O(nr) numbers instead of Powell's nr^2 direction set. Line minimisation by
// quadratic interpolation through f(-delta), f(0), f(+delta) (Powell 1964),
// clamped so that e stays >= 0, accepted only when f decreases; f along a
// line is exactly quadratic, so one pass of three sums gives every trial
// value (one block reduction per direction on the GPU). Coarse to
// fine: texels grouped by `coarsest`, then halves of it, down to single texels.
#include <math.h>

#include "core/hd.h"

namespace nebula {

// The column problem's matrix, column-major: a[i * n + j] = A[j, i], with
// A[j, i] = 0 for j >= row_end[i] and for i < col_begin[j].
struct ColumnSystem {
  int n = 0;
  const float* a = nullptr;
  const int* row_end = nullptr;
  const int* col_begin = nullptr;
};

struct PowellSettings {
  int coarsest = 64;        // texels per group at the first level (a power of two, >= 1)
  int sweeps = 30;          // sweeps per level at most
  float tolerance = 1e-5f;  // a level ends when a sweep lowers f by less than this fraction of f
};

// Scratch of 6 n floats (n = system.n): the map column comes back in e.
struct PowellWork {
  float* e;
  float* e0;  // e at the sweep's start
  float* r;   // A e - p
  float* g;   // the group's image A[:, group] 1
  float* d;   // the sweep's displacement
  float* ad;  // A d
};

// One thread: the CPU's team.
struct SerialTeam {
  NEBULA_HD int rank() const { return 0; }
  NEBULA_HD int size() const { return 1; }
  NEBULA_HD void sync() {}
  template <int K>
  NEBULA_HD void sum(float (&)[K]) {}  // one thread: its sums are the totals
};

namespace powell_detail {

// The minimiser of the parabola through (-delta, fm), (0, f0), (delta, fp),
// or the better end point when it opens downwards; clamped to [lo, hi].
NEBULA_HD float parabola_minimum(float fm, float f0, float fp, float delta, float lo, float hi) {
  const float curvature = fp + fm - 2.0f * f0;  // 2 c delta^2
  float alpha;
  if (curvature > 0.0f)
    alpha = 0.5f * delta * (fm - fp) / curvature;
  else
    alpha = fp < fm ? delta : -delta;
  return alpha < lo ? lo : (alpha > hi ? hi : alpha);
}

// One line minimisation along a direction whose image is d. The synthesis
// along the line, r + alpha d, makes f quadratic in alpha: with the sums
// s = {sum r^2, sum r d, sum d^2} over the rows d touches, f(alpha) = f -
// s0 + (s0 + 2 alpha s1 + alpha^2 s2) for every trial alpha. Powell's
// interpolation through f(-delta), f(0), f(delta) then gives the step,
// clamped to [lo, hi] (non-negativity) and taken only when f falls. Returns
// the step (0: none) and the new f.
NEBULA_HD float line_minimum(const float (&s)[3], float f, float delta, float lo, float hi, float& f_new) {
  auto trial = [&](float alpha) { return f - s[0] + (s[0] + 2.0f * alpha * s[1] + alpha * alpha * s[2]); };
  const float alpha = parabola_minimum(trial(-delta), f, trial(delta), delta, lo, hi);
  f_new = f;
  if (!(alpha != 0.0f)) return 0.0f;
  const float candidate = trial(alpha);
  if (!(candidate < f)) return 0.0f;
  f_new = candidate;
  return alpha;
}

}  // namespace powell_detail

// Fits e >= 0 to the column p (n values). Every thread of the team calls it
// with the same arguments; work lies in memory the team shares. A thread owns
// the rows j = rank + k size of r, g and ad (it alone writes and reads them),
// so only e and d, read across rows, need the team's barriers. Returns the
// sweeps run in all.
template <class Team>
NEBULA_HD int powell_column(Team& team, const ColumnSystem& A, const float* p, const PowellSettings& s,
                            const PowellWork& w) {
  using namespace powell_detail;
  const int n = A.n;
  float f;
  {
    float sq[1] = {0.0f};
    for (int j = team.rank(); j < n; j += team.size()) {
      w.e[j] = 0.0f;
      w.r[j] = -p[j];
      sq[0] += p[j] * p[j];
    }
    team.sum(sq);
    f = sq[0];
  }
  int sweeps_run = 0;
  if (!(f > 0.0f)) return 0;
  for (int g = s.coarsest; g >= 1; g /= 2) {
    for (int sweep = 0; sweep < s.sweeps && f > 0.0f; ++sweep) {
      ++sweeps_run;
      const float f_start = f;
      for (int j = team.rank(); j < n; j += team.size()) w.e0[j] = w.e[j];
      team.sync();
      for (int i0 = 0; i0 < n; i0 += g) {
        const int i1 = i0 + g < n ? i0 + g : n;
        int rows = 0;
        for (int i = i0; i < i1; ++i) rows = A.row_end[i] > rows ? A.row_end[i] : rows;
        // The group's common value, read before the barrier in team.sum: after
        // it, other threads may already write the group's texels.
        const float level = w.e[i0];
        float sums[3] = {0.0f, 0.0f, 0.0f};
        for (int j = team.rank(); j < rows; j += team.size()) {
          float v = 0.0f;  // the group's image: sum of its texels' columns of A
          for (int i = i0; i < i1; ++i) v += A.a[size_t(i) * n + j];
          w.g[j] = v;
          sums[0] += w.r[j] * w.r[j];
          sums[1] += w.r[j] * v;
          sums[2] += v * v;
        }
        team.sum(sums);
        if (!(sums[2] > 0.0f)) continue;
        const float delta = fabsf(level) + sqrtf(f / sums[2]);
        float f_new;
        const float alpha = line_minimum(sums, f, delta, -level, 1e30f, f_new);
        if (alpha != 0.0f) {
          for (int j = team.rank(); j < rows; j += team.size()) w.r[j] += alpha * w.g[j];
          for (int i = i0 + team.rank(); i < i1; i += team.size()) w.e[i] = fmaxf(0.0f, level + alpha);
          f = f_new;
        }
      }
      // Powell's extrapolation along the sweep's displacement d, bounded so
      // that e + alpha d stays >= 0.
      team.sync();
      for (int j = team.rank(); j < n; j += team.size()) w.d[j] = w.e[j] - w.e0[j];
      team.sync();
      float sums[3] = {0.0f, 0.0f, 0.0f};
      for (int j = team.rank(); j < n; j += team.size()) {
        float v = 0.0f;
        for (int i = A.col_begin[j]; i < n; ++i) v += A.a[size_t(i) * n + j] * w.d[i];
        w.ad[j] = v;
        sums[0] += w.r[j] * w.r[j];
        sums[1] += w.r[j] * v;
        sums[2] += v * v;
      }
      // Step limits: alpha in [lo, hi] keeps e + alpha d >= 0. Every thread
      // scans the whole column before the barrier in team.sum (after it e
      // changes), so no reduction is needed.
      float lo = -1e30f, hi = 1e30f;
      for (int i = 0; i < n; ++i) {
        const float di = w.d[i];
        if (di < 0.0f) hi = fminf(hi, w.e[i] / -di);
        if (di > 0.0f) lo = fmaxf(lo, -w.e[i] / di);
      }
      team.sum(sums);
      if (sums[2] > 0.0f && hi > lo && hi > 0.0f) {
        float f_new;
        const float alpha = line_minimum(sums, f, 1.0f, lo, hi, f_new);
        if (alpha != 0.0f) {
          for (int j = team.rank(); j < n; j += team.size()) {
            w.r[j] += alpha * w.ad[j];
            w.e[j] = fmaxf(0.0f, w.e[j] + alpha * w.d[j]);
          }
          f = f_new;
        }
      }
      team.sync();
      if (!(f_start - f > s.tolerance * f_start)) break;
    }
  }
  return sweeps_run;
}

}  // namespace nebula
