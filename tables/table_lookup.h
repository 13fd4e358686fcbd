#pragma once
#include <type_traits>
#include <vector>

#include "core/angular_binning.h"
#include "core/hd.h"
#include "core/math.h"

namespace nebula {

struct ScatteringTable;

// A non-owning view of P for lookups on host or device: P points to host
// memory (view_of) or device memory (place_table with a device placement).
struct TableView {
  const float* P = nullptr;  // row-major [n_tau][n_mu]
  // Each row's integral of the lookup's interpolant in the bin coordinate u,
  // from u = -1/2 to bin centre k (cumulative_rows): mean_over_angles' O(1)
  // means. May be null (then that mean falls back to one lookup).
  const float* C = nullptr;
  int n_tau = 0;
  int n_mu = 0;
  float tau_max = 0.0f;
  float tau_scale = 0.0f;  // (n_tau - 1) / tau_max (0 when tau_max is): a row found by a product, not a division
  AngularBins bins;

  // Bilinear in (tau, bin coordinate): linear in tau between rows and linear
  // between bin centres. Beyond the outermost centres mu holds the edge value
  // (still inside the mu domain, so not a clamp). A tau_sct above tau_max, a
  // negative or NaN tau_sct, or a NaN mu is clamped to the table and counted
  // once in *clamped, so callers can report how often they left the table.
  NEBULA_HD float lookup(float tau_sct, float mu, int* clamped = nullptr) const {
    return lookup_at(tau_sct, angle_coordinate(mu), clamped);
  }

  // The continuous bin-centre index of mu (kNoAngle for a NaN mu). Callers
  // looking up several rows at one angle (bands) compute it once: for
  // uniform-theta bins it costs an acos.
  static constexpr float kNoAngle = -1.0f;
  NEBULA_HD float angle_coordinate(float mu) const {
    return mu == mu ? bins.position(mu) - 0.5f : kNoAngle;
  }

  // The bin centres around an angle coordinate and the fraction between them:
  // what every table of the same bins shares at one angle (angle_cell).
  struct AngleCell {
    int k0 = 0, k1 = 0;
    float fu = 0.0f;
    bool none = true;  // kNoAngle: looked up at u = 0 and counted as a clamp
  };
  NEBULA_HD AngleCell angle_cell(float u) const {
    AngleCell c;
    c.none = u < -0.75f;  // kNoAngle: positions are never below -0.5
    cell(c.none ? 0.0f : u, n_mu, c.k0, c.fu);
    c.k1 = c.k0 + 1 < n_mu ? c.k0 + 1 : c.k0;
    return c;
  }

  // lookup() with the angle given as angle_coordinate(mu).
  NEBULA_HD float lookup_at(float tau_sct, float u, int* clamped = nullptr) const {
    return lookup_at(tau_sct, angle_cell(u), clamped);
  }

  // The same with the angle's cell, from angle_cell of a table with these bins.
  NEBULA_HD float lookup_at(float tau_sct, const AngleCell& a, int* clamped = nullptr) const {
    if (P == nullptr || n_tau < 1 || n_mu < 1) return 0.0f;
    int i0, i1;
    float ft;
    const bool outside = rows(tau_sct, i0, i1, ft) || a.none;
    if (outside && clamped != nullptr) *clamped += 1;
    // Weighted form (not a + f (b - a)): exact at grid nodes and free of
    // cancellation for non-negative P.
    const float fu = a.fu;
    const float* row0 = P + static_cast<long long>(i0) * n_mu;
    const float* row1 = P + static_cast<long long>(i1) * n_mu;
    const float v0 = (1.0f - fu) * row0[a.k0] + fu * row0[a.k1];
    const float v1 = (1.0f - fu) * row1[a.k0] + fu * row1[a.k1];
    return (1.0f - ft) * v0 + ft * v1;
  }

  // The mean of the lookup's interpolant over the bin coordinates [u0, u1]
  // (u0 < u1, both within [-1/2, n_mu - 1/2]): for uniform-theta bins the
  // mean over the angles in between. Two integrals per row from C, no loop.
  NEBULA_HD float mean_over_angles(float tau_sct, float u0, float u1, int* clamped = nullptr) const {
    if (P == nullptr || n_tau < 1 || n_mu < 1) return 0.0f;
    if (C == nullptr || !(u1 > u0)) return lookup_at(tau_sct, 0.5f * (u0 + u1), clamped);
    int i0, i1;
    float ft;
    if (rows(tau_sct, i0, i1, ft) && clamped != nullptr) *clamped += 1;
    const float inv = 1.0f / (u1 - u0);
    const float m0 = (integral_to(i0, u1) - integral_to(i0, u0)) * inv;
    const float m1 = (integral_to(i1, u1) - integral_to(i1, u0)) * inv;
    return (1.0f - ft) * m0 + ft * m1;
  }

  NEBULA_HD float at(int i_tau, int k_mu) const {
    return P[static_cast<long long>(i_tau) * n_mu + k_mu];
  }

 private:
  // The rows around tau_sct and the fraction between them (tau clamped to
  // the table); true when it was clamped (above tau_max, negative or NaN).
  NEBULA_HD bool rows(float tau_sct, int& i0, int& i1, float& ft) const {
    bool outside = false;
    float tau = tau_sct;
    if (!(tau >= 0.0f)) {  // negative or NaN
      tau = 0.0f;
      outside = true;
    } else if (tau > tau_max) {
      tau = tau_max;
      outside = true;
    }
    // The tau axis is uniform, so the row is found in O(1).
    const float x = tau * tau_scale;
    cell(x, n_tau, i0, ft);
    i1 = i0 + 1 < n_tau ? i0 + 1 : i0;
    return outside;
  }

  // Row i's integral of the interpolant from u = -1/2 to u: P_0 below the
  // first centre, linear between centres, P_(n-1) beyond the last.
  NEBULA_HD float integral_to(int i, float u) const {
    const float* p = P + static_cast<long long>(i) * n_mu;
    const float* c = C + static_cast<long long>(i) * n_mu;
    if (!(u > 0.0f)) return (fmaxf(u, -0.5f) + 0.5f) * p[0];
    if (u >= float(n_mu - 1)) return c[n_mu - 1] + (fminf(u, float(n_mu) - 0.5f) - float(n_mu - 1)) * p[n_mu - 1];
    const int k = static_cast<int>(u);
    const float f = u - static_cast<float>(k);
    return c[k] + f * p[k] + 0.5f * f * f * (p[k + 1] - p[k]);
  }

  // Splits a node coordinate x (clamped to [0, n - 1]) into a lower node
  // index and the fraction towards the next one; at x = n - 1 that is node
  // n - 2 with fraction 1, so the last node is reproduced exactly.
  NEBULA_HD static void cell(float x, int n, int& index, float& fraction) {
    x = clamp(x, 0.0f, static_cast<float>(n - 1));
    int i = static_cast<int>(x);
    if (i > n - 2) i = n - 2;
    if (i < 0) i = 0;
    index = i;
    fraction = x - static_cast<float>(i);
  }
};

// Passed by value to kernels.
static_assert(std::is_trivially_copyable_v<TableView>);

// Each row's running integral of the lookup's interpolant over the bin
// coordinate, at the bin centres: C_0 = P_0 / 2, C_(k+1) = C_k + (P_k +
// P_(k+1)) / 2 (summed in double), row-major like P.
std::vector<float> cumulative_rows(const ScatteringTable& table);

// A host view of table.P; throws Error when P's size is not n_tau x n_mu
// or n_tau < 2, so lookups can never read out of bounds. The table must
// outlive the view.
TableView view_of(const ScatteringTable& table);

// The view of `table` with P placed by `place` (core/placement.h): the
// table's own array on the host, a device copy on the GPU.
template <class Table, class Place>
TableView place_table(const Table& table, Place& place) {
  TableView view = view_of(table);
  view.P = place.place(table.P, table.device_P);  // uploaded once for every frame
  view.C = place.place_mirrored(table.device_C, table.P.size(), [&] { return cumulative_rows(table); });
  return view;
}

}  // namespace nebula
