#pragma once
// Ours beside the thesis' Powell search: the emission-only model is linear in
// the map (projection.h), so each image column is a non-negative least-squares
// problem (the thesis' own future-work suggestion),
//   min ||A x - p||^2 + lambda ||D x||^2  over x >= 0,
// with D the first differences along r (Tikhonov smoothing for noisy images;
// lambda = 0 for clean ones). Solved exactly by block principal pivoting
// (Kim & Park 2011, an active-set method of the Lawson-Hanson family that
// exchanges many variables per step) on the Gram matrix G = A^T A + lambda
// D^T D, which every column shares; warm-started from the unconstrained
// solution's positive set. Host only (Eigen, double precision).
#include <Eigen/Dense>

#include "reconstruct/projection.h"

namespace nebula {

struct NnlsResult {
  int iterations = 0;     // pivoting steps
  bool converged = false;
  double tolerance = 0;   // the KKT tolerance the stop used (see ColumnNnls::solve)
  double min_gradient = 0;  // min over zero x_i of the gradient y_i (>= -tolerance when converged)
};

class ColumnNnls {
 public:
  // `smoothness` is lambda relative to the data term's scale: lambda =
  // smoothness * trace(A^T A) / trace(D^T D), so the same value means the
  // same balance at every map size.
  ColumnNnls(const ColumnProjection& projection, double smoothness);

  // x (n values) for the column p (n values). Stops when the KKT conditions
  // hold: x_i >= 0 (exactly: the free set's x solved directly is positive)
  // and the gradient y = G x - A^T p >= -tol on the zero set, with
  // tol = 1e3 n eps_double (||A^T p||_inf + ||G||_max ||x||_1), the rounding
  // of y. Thread-safe.
  NnlsResult solve(const float* p, float* x) const;

  double lambda() const { return lambda_; }
  const Eigen::MatrixXd& matrix() const { return a_; }

 private:
  int n_;
  double lambda_;
  Eigen::MatrixXd a_, gram_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

}  // namespace nebula
