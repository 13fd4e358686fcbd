#pragma once
// A filter's transmission S(lambda) (or any spectral weight) as a piecewise
// polynomial, the form the report's analytic integral takes (Barrès 2023,
// "filters as polynomials"): on segment i, lambda in [break_i, break_(i+1)],
// S = sum_k c_ik lambda^k (global powers, lambda in um: what Algorithm 1
// integrates against e^(-a/lambda)), zero outside the breaks.
#include <functional>
#include <string>
#include <vector>

#include "core/hd.h"
#include "illumination/passband.h"

namespace nebula::spectral {

constexpr int kMaxPolynomialDegree = 3;

struct PiecewisePolynomial {
  int degree = kMaxPolynomialDegree;
  std::vector<double> breaks;        // um, ascending, segments + 1
  std::vector<double> coefficients;  // [segment][degree + 1], global powers of lambda (um)
  int segments() const { return breaks.empty() ? 0 : int(breaks.size()) - 1; }
  double operator()(double lambda_um) const;
};

// What a fit achieved against the measured curve (its linear interpolant).
struct FitReport {
  int segments = 0;
  double max_error = 0;       // max |fit - measured| / peak of measured
  double integral_error = 0;  // |integral fit - integral measured| / integral measured
};

// Least-squares cubic on each of n uniform segments of the passband's support,
// the number of segments doubled from 4 until the largest error is at most
// `tolerance` of the peak (or 512 segments). The measured curve is linear
// between its rows, so a narrow dip needs more segments: the report says how
// many and the error reached.
PiecewisePolynomial fit_passband(const Passband& passband, double tolerance = 2e-3, FitReport* report = nullptr);

// A least-squares cubic on each of `segments` uniform segments of [lo, hi] um
// of any function.
PiecewisePolynomial fit_function(const std::function<double(double)>& f, double lo_um, double hi_um, int segments);
// The same on the segments between given breaks (um, ascending): e.g. a
// filter's measured curve times a star's spectrum on the filter's own rows,
// where the curve is exactly linear (Algorithm 1, spectral_model.cpp).
PiecewisePolynomial fit_on_breaks(const std::function<double(double)>& f, const std::vector<double>& breaks);

// The measured curve itself: linear between its rows, zero outside; lambda in um.
double measured_response(const Passband& passband, double lambda_um);

// The device's view of a piecewise polynomial.
struct PolynomialView {
  const double* breaks = nullptr;
  const double* coefficients = nullptr;
  int segments = 0, degree = 0;
};
inline PolynomialView view_of(const PiecewisePolynomial& p) {
  return {p.breaks.data(), p.coefficients.data(), p.segments(), p.degree};
}

}  // namespace nebula::spectral
