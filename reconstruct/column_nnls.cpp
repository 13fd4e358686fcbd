#include "reconstruct/column_nnls.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/error.h"

namespace nebula {

ColumnNnls::ColumnNnls(const ColumnProjection& projection, double smoothness) : n_(projection.n) {
  if (!(smoothness >= 0.0) || !std::isfinite(smoothness))
    throw ParameterError("smoothness", "is " + to_text(smoothness) + "; must be finite and >= 0");
  a_.resize(n_, n_);
  for (int i = 0; i < n_; ++i)
    for (int j = 0; j < n_; ++j) a_(j, i) = projection.at(j, i);
  gram_ = a_.transpose() * a_;
  lambda_ = 0.0;
  if (smoothness > 0.0 && n_ > 1) {
    // D^T D of the first differences: the tridiagonal (1, -1; -1, 2, -1; ...; -1, 1), trace 2 (n - 1).
    lambda_ = smoothness * gram_.trace() / (2.0 * (n_ - 1));
    for (int i = 0; i < n_; ++i) {
      gram_(i, i) += lambda_ * ((i == 0 || i == n_ - 1) ? 1.0 : 2.0);
      if (i + 1 < n_) {
        gram_(i, i + 1) -= lambda_;
        gram_(i + 1, i) -= lambda_;
      }
    }
  }
  llt_.compute(gram_);
  if (llt_.info() != Eigen::Success) throw Error("reconstruct: the column matrix is singular (no texel is seen)");
}

NnlsResult ColumnNnls::solve(const float* p, float* out) const {
  const int n = n_;
  Eigen::VectorXd pv(n);
  for (int j = 0; j < n; ++j) pv(j) = p[j];
  const Eigen::VectorXd c = a_.transpose() * pv;
  Eigen::VectorXd x = llt_.solve(c);  // unconstrained: its positive set starts the pivoting
  std::vector<char> is_free(static_cast<size_t>(n), 0);
  for (int i = 0; i < n; ++i) is_free[size_t(i)] = x(i) > 0.0;
  const double g_max = gram_.cwiseAbs().maxCoeff();
  const double eps = std::numeric_limits<double>::epsilon();
  NnlsResult result;
  int best_infeasible = n + 1, backup = 3;
  const int max_iterations = 10 * n + 10;
  std::vector<int> idx;
  Eigen::VectorXd y(n);
  for (result.iterations = 0; result.iterations < max_iterations; ++result.iterations) {
    idx.clear();
    for (int i = 0; i < n; ++i)
      if (is_free[size_t(i)]) idx.push_back(i);
    x.setZero();
    if (int(idx.size()) == n) {
      x = llt_.solve(c);
    } else if (!idx.empty()) {
      const Eigen::MatrixXd sub = gram_(idx, idx);
      const Eigen::VectorXd rhs = c(idx);
      const Eigen::VectorXd xf = sub.llt().solve(rhs);
      for (size_t k = 0; k < idx.size(); ++k) x(idx[k]) = xf(Eigen::Index(k));
    }
    y = gram_ * x - c;
    const double tol = 1e3 * n * eps * (c.cwiseAbs().maxCoeff() + g_max * x.cwiseAbs().sum());
    result.tolerance = tol;
    std::vector<int> infeasible;
    for (int i = 0; i < n; ++i)
      if (is_free[size_t(i)] ? x(i) < 0.0 : y(i) < -tol) infeasible.push_back(i);
    if (infeasible.empty()) {
      result.converged = true;
      break;
    }
    // Block exchange while the infeasible count falls; after three steps
    // without progress, exchange only the largest index (Murty's rule),
    // which cannot cycle.
    if (int(infeasible.size()) < best_infeasible) {
      best_infeasible = int(infeasible.size());
      backup = 3;
      for (int i : infeasible) is_free[size_t(i)] = !is_free[size_t(i)];
    } else if (backup > 0) {
      --backup;
      for (int i : infeasible) is_free[size_t(i)] = !is_free[size_t(i)];
    } else {
      const int i = infeasible.back();
      is_free[size_t(i)] = !is_free[size_t(i)];
    }
  }
  double min_gradient = 0.0;
  for (int i = 0; i < n; ++i) {
    if (!is_free[size_t(i)]) min_gradient = std::min(min_gradient, y(i));
    out[i] = static_cast<float>(std::max(0.0, x(i)));
  }
  result.min_gradient = min_gradient;
  return result;
}

}  // namespace nebula
