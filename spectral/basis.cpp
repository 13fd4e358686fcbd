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

}  // namespace nebula::spectral
