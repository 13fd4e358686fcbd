#include "spectral/piecewise_polynomial.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace nebula::spectral {

double measured_response(const Passband& p, double lambda_um) {
  const double nm = lambda_um * 1000.0;
  const std::vector<double>& x = p.wavelength_nm;
  if (nm < x.front() || nm > x.back()) return 0.0;
  const size_t i = std::min<size_t>(std::upper_bound(x.begin(), x.end(), nm) - x.begin(), x.size() - 1);
  if (i == 0) return p.response[0];
  const double u = (nm - x[i - 1]) / (x[i] - x[i - 1]);
  return (1 - u) * p.response[i - 1] + u * p.response[i];
}

namespace {

// Solves the 4x4 (or smaller) normal equations by Gaussian elimination with pivoting.
void solve(int n, double a[4][5]) {
  for (int c = 0; c < n; ++c) {
    int pivot = c;
    for (int r = c + 1; r < n; ++r)
      if (std::fabs(a[r][c]) > std::fabs(a[pivot][c])) pivot = r;
    for (int k = 0; k <= n; ++k) std::swap(a[c][k], a[pivot][k]);
    for (int r = 0; r < n; ++r) {
      if (r == c || a[c][c] == 0.0) continue;
      const double f = a[r][c] / a[c][c];
      for (int k = c; k <= n; ++k) a[r][k] -= f * a[c][k];
    }
  }
  for (int r = 0; r < n; ++r) a[r][n] = a[r][r] != 0.0 ? a[r][n] / a[r][r] : 0.0;
}

}  // namespace

PiecewisePolynomial fit_on_breaks(const std::function<double(double)>& fn, const std::vector<double>& breaks) {
  PiecewisePolynomial out;
  out.degree = kMaxPolynomialDegree;
  const int n = out.degree + 1;
  constexpr int kSamples = 64;
  out.breaks = breaks;
  for (size_t s = 0; s + 1 < breaks.size(); ++s) {
    const double a = out.breaks[s], b = out.breaks[s + 1], mid = 0.5 * (a + b), half = 0.5 * (b - a);
    // Least squares in t = (lambda - mid) / half on [-1, 1] (well conditioned),
    // then expanded to global powers of lambda.
    double m[4][5] = {};
    for (int k = 0; k < kSamples; ++k) {
      const double t = -1.0 + 2.0 * (k + 0.5) / kSamples;
      const double y = fn(mid + half * t);
      double pw[4] = {1, t, t * t, t * t * t};
      for (int r = 0; r < n; ++r) {
        for (int c = 0; c < n; ++c) m[r][c] += pw[r] * pw[c];
        m[r][n] += pw[r] * y;
      }
    }
    solve(n, m);
    // sum_j d_j ((lambda - mid)/half)^j -> sum_k c_k lambda^k
    double c[4] = {};
    for (int j = 0; j < n; ++j) {
      const double dj = m[j][n] / std::pow(half, j);
      // (lambda - mid)^j = sum_k binom(j,k) lambda^k (-mid)^(j-k)
      double binom = 1.0;
      for (int k = 0; k <= j; ++k) {
        c[k] += dj * binom * std::pow(-mid, j - k);
        binom = binom * (j - k) / (k + 1);
      }
    }
    for (int k = 0; k < n; ++k) out.coefficients.push_back(c[k]);
  }
  return out;
}

PiecewisePolynomial fit_function(const std::function<double(double)>& fn, double lo, double hi, int segments) {
  std::vector<double> breaks;
  for (int s = 0; s <= segments; ++s) breaks.push_back(lo + (hi - lo) * s / segments);
  breaks.back() = hi;
  return fit_on_breaks(fn, breaks);
}

namespace {
PiecewisePolynomial fit_with(const Passband& p, int segments) {
  return fit_function([&](double l) { return measured_response(p, l); }, p.wavelength_nm.front() / 1000.0,
                      p.wavelength_nm.back() / 1000.0, segments);
}
}  // namespace

double PiecewisePolynomial::operator()(double lambda) const {
  if (breaks.empty() || lambda < breaks.front() || lambda > breaks.back()) return 0.0;
  const int s = std::min<int>(int(std::upper_bound(breaks.begin(), breaks.end(), lambda) - breaks.begin()) - 1,
                              segments() - 1);
  double v = 0.0;
  for (int k = degree; k >= 0; --k) v = v * lambda + coefficients[size_t(s) * (degree + 1) + k];
  return v;
}

PiecewisePolynomial fit_passband(const Passband& p, double tolerance, FitReport* report) {
  double peak = 0.0;
  for (double r : p.response) peak = std::max(peak, r);
  if (!(peak > 0.0)) throw Error("passband '" + p.name + "' has no response to fit");
  const double lo = p.wavelength_nm.front() / 1000.0, hi = p.wavelength_nm.back() / 1000.0;
  PiecewisePolynomial fit;
  FitReport r;
  for (int segments = 4;; segments *= 2) {
    fit = fit_with(p, segments);
    r.segments = segments;
    r.max_error = 0.0;
    double fit_sum = 0.0, measured_sum = 0.0;
    constexpr int kChecks = 20000;
    for (int k = 0; k <= kChecks; ++k) {
      const double lambda = lo + (hi - lo) * k / kChecks;
      const double f = fit(lambda), m = measured_response(p, lambda);
      r.max_error = std::max(r.max_error, std::fabs(f - m) / peak);
      fit_sum += f;
      measured_sum += m;
    }
    r.integral_error = std::fabs(fit_sum - measured_sum) / measured_sum;
    if (r.max_error <= tolerance || segments >= 512) break;
  }
  if (report) *report = r;
  return fit;
}

}  // namespace nebula::spectral
