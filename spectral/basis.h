#pragma once
// The optimal basis of Barrès (2023): a greedy choice, with Gram-Schmidt,
// of a few members of a family of spectral functions, such that every member
// is close to its projection on their span (Algorithm 2, "FindBestMonome" over
// a discretised family). The family is e^(-a kappa(lambda)) over optical paths
// a for one star spectrum (Algorithms 3-4), or s_T(lambda) e^(-a kappa(lambda))
// over optical path and star temperature (the light-density basis, Algorithm
// 5). Functions live on a wavelength grid with trapezoid weights: the inner
// product is the L2 one over the grid's range.
#include <functional>
#include <vector>

namespace nebula::spectral {

// A wavelength grid over [lo, hi] um with n >= 2 uniform nodes and trapezoid weights.
struct WavelengthGrid {
  std::vector<double> lambda, weight;
  static WavelengthGrid uniform(double lo_um, double hi_um, int n);
  double dot(const std::vector<double>& a, const std::vector<double>& b) const;
  double norm(const std::vector<double>& a) const;
};

struct GreedyBasis {
  std::vector<int> chosen;                // family indices, in the order chosen
  std::vector<std::vector<double>> phi;   // orthonormal elements on the grid
  // error[n]: the largest L2 residual ||f - P_n f|| over the family (normalised
  // members) with the first n elements (n = 0 .. size); member_error[n][m]
  // each member's, the curves of the report's Figs. 4.1-4.4.
  std::vector<double> error;
  std::vector<std::vector<double>> member_error;
  int size() const { return int(phi.size()); }
};

// Algorithm 2 on a family given on the grid, members as given (the report's
// absolute L2 error: members of small norm, light that arrives attenuated,
// weigh less). `first` forces the first element
// (the report starts from the constant e^0 = 1: no dust); -1 lets the greedy
// choose it too. Stops at n elements or when the largest residual falls below
// 1e-12 (the family's span is then exhausted).
GreedyBasis greedy_basis(const WavelengthGrid& grid, const std::vector<std::vector<double>>& family, int n,
                         int first = 0);

// Coefficients <f, phi_j> of f on the basis (the orthogonal projection:
// least absolute L2 error).
std::vector<double> project(const WavelengthGrid& grid, const GreedyBasis& basis, const std::vector<double>& f);

// Coefficients c of the least *relative* error: min integral ((f - sum c_j phi_j) / f)^2
// d lambda, f > 0 on the grid (values below 1e-200 of its peak are floored there).
// Where f spans decades (e^(-kappa D) at large D), the orthogonal projection
// leaves a residual of the size of f's peak in the wavelengths where f is
// small, a large relative error in every filter there; this one keeps the
// error relative everywhere (docs/spectral.md, "Relative projection").
// Householder QR on the weighted system (the weights span many decades: normal
// equations would square their condition).
std::vector<double> project_relative(const WavelengthGrid& grid, const GreedyBasis& basis,
                                     const std::vector<double>& f);
// The same with the error measured relative to an envelope e > 0 instead of f
// itself: for functions that cross zero (a centred power of kappa times
// e^(-kappa D)), whose sum with the envelope's own term is what a pixel sees.
std::vector<double> project_relative(const WavelengthGrid& grid, const GreedyBasis& basis, const std::vector<double>& f,
                                     const std::vector<double>& envelope);

}  // namespace nebula::spectral
