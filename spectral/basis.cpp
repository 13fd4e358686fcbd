#include "spectral/basis.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace nebula::spectral {

WavelengthGrid WavelengthGrid::uniform(double lo, double hi, int n) {
  if (!(hi > lo) || n < 2) throw Error("wavelength grid: needs hi > lo and at least 2 nodes");
  WavelengthGrid g;
  const double h = (hi - lo) / (n - 1);
  for (int i = 0; i < n; ++i) {
    g.lambda.push_back(i == n - 1 ? hi : lo + h * i);
    g.weight.push_back(i == 0 || i == n - 1 ? 0.5 * h : h);
  }
  return g;
}

double WavelengthGrid::dot(const std::vector<double>& a, const std::vector<double>& b) const {
  double s = 0.0;
  for (size_t i = 0; i < weight.size(); ++i) s += weight[i] * a[i] * b[i];
  return s;
}

double WavelengthGrid::norm(const std::vector<double>& a) const { return std::sqrt(dot(a, a)); }

GreedyBasis greedy_basis(const WavelengthGrid& grid, const std::vector<std::vector<double>>& family, int n,
                         int first) {
  if (n < 1) throw Error("basis size must be at least 1, got " + std::to_string(n));
  if (family.empty()) throw Error("greedy basis: the family is empty");
  // Residuals of the normalised members, updated by one Gram-Schmidt step per
  // element chosen (modified Gram-Schmidt: stable in double).
  std::vector<std::vector<double>> residual = family;
  GreedyBasis basis;
  auto record = [&] {
    std::vector<double> e(residual.size());
    for (size_t m = 0; m < residual.size(); ++m) e[m] = grid.norm(residual[m]);
    basis.member_error.push_back(e);
    basis.error.push_back(*std::max_element(e.begin(), e.end()));
  };
  record();
  for (int k = 0; k < n; ++k) {
    int pick = k == 0 && first >= 0 ? first : -1;
    if (pick < 0) pick = int(std::max_element(basis.member_error.back().begin(), basis.member_error.back().end()) -
                             basis.member_error.back().begin());
    const double norm = basis.member_error.back()[size_t(pick)];
    if (!(norm > 1e-12)) break;
    std::vector<double> phi = residual[size_t(pick)];
    for (double& v : phi) v /= norm;
    // Re-orthogonalise once against the elements so far (twice is enough).
    for (const auto& q : basis.phi) {
      const double c = grid.dot(phi, q);
      for (size_t i = 0; i < phi.size(); ++i) phi[i] -= c * q[i];
    }
    const double renorm = grid.norm(phi);
    for (double& v : phi) v /= renorm;
    for (auto& r : residual) {
      const double c = grid.dot(r, phi);
      for (size_t i = 0; i < r.size(); ++i) r[i] -= c * phi[i];
    }
    basis.chosen.push_back(pick);
    basis.phi.push_back(std::move(phi));
    record();
  }
  return basis;
}

std::vector<double> project(const WavelengthGrid& grid, const GreedyBasis& basis, const std::vector<double>& f) {
  std::vector<double> c;
  for (const auto& q : basis.phi) c.push_back(grid.dot(f, q));
  return c;
}

std::vector<double> project_relative(const WavelengthGrid& grid, const GreedyBasis& basis,
                                     const std::vector<double>& f) {
  return project_relative(grid, basis, f, f);
}

std::vector<double> project_relative(const WavelengthGrid& grid, const GreedyBasis& basis, const std::vector<double>& f,
                                     const std::vector<double>& envelope) {
  const size_t G = f.size(), N = basis.phi.size();
  double peak = 0.0;
  for (double v : envelope) peak = std::max(peak, std::fabs(v));
  if (!(peak > 0.0)) return std::vector<double>(N, 0.0);
  // Rows sqrt(w_i) phi_j(i) / e_i, right-hand side sqrt(w_i) f_i / e_i: the residual of row i
  // is sqrt(w_i) (f_i - sum c_j phi_j(i)) / e_i.
  std::vector<std::vector<double>> a(N, std::vector<double>(G));  // columns
  std::vector<double> b(G);
  for (size_t i = 0; i < G; ++i) {
    const double ei = std::max(std::fabs(envelope[i]), 1e-200 * peak);
    const double s = std::sqrt(grid.weight[i]) / ei;
    for (size_t j = 0; j < N; ++j) a[j][i] = basis.phi[j][i] * s;
    b[i] = f[i] * s;
  }
  // Householder QR, column by column; b transformed alongside.
  std::vector<double> diag(N);
  for (size_t k = 0; k < N; ++k) {
    double norm = 0.0;
    for (size_t i = k; i < G; ++i) norm += a[k][i] * a[k][i];
    norm = std::sqrt(norm);
    const double alpha = a[k][k] > 0.0 ? -norm : norm;
    diag[k] = alpha;
    if (norm == 0.0) continue;
    std::vector<double> v(a[k].begin() + std::ptrdiff_t(k), a[k].end());
    v[0] -= alpha;
    double vv = 0.0;
    for (double x : v) vv += x * x;
    if (vv == 0.0) continue;
    const auto reflect = [&](std::vector<double>& col) {
      double d = 0.0;
      for (size_t i = k; i < G; ++i) d += v[i - k] * col[i];
      d *= 2.0 / vv;
      for (size_t i = k; i < G; ++i) col[i] -= d * v[i - k];
    };
    for (size_t j = k + 1; j < N; ++j) reflect(a[j]);
    reflect(b);
  }
  // Back substitution on R c = Q^T b (a column with no length left gets 0).
  std::vector<double> c(N, 0.0);
  for (size_t k = N; k-- > 0;) {
    double s = b[k];
    for (size_t j = k + 1; j < N; ++j) s -= a[j][k] * c[j];
    c[k] = std::fabs(diag[k]) > 1e-300 ? s / diag[k] : 0.0;
  }
  return c;
}

}  // namespace nebula::spectral
