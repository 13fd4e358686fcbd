#pragma once
// Star spectra for the spectral system (Barrès 2023: stars as black bodies),
// wavelengths in um. Spectra are shapes per unit wavelength normalised over
// all wavelengths (integral 1, 1/um), so a star of bolometric luminosity L
// emits L * s(lambda) L_sun/um: the convention of the band powers
// (illumination/star.h, energy weighting).
#include <cmath>
#include <string>
#include <vector>

#include "core/hd.h"

namespace nebula::spectral {

// Second radiation constant h c / k_B in um K (CODATA 2018, exact SI constants).
constexpr double kC2 = 14387.768775039337;
constexpr double kPi = 3.14159265358979323846;

// Planck's B_lambda(T) normalised to integral 1 over all lambda:
// 15 / pi^4 (c2/T)^4 lambda^-5 / (e^(c2/(lambda T)) - 1), 1/um.
NEBULA_HD double planck_shape(double lambda_um, double T) {
  const double b = kC2 / T, x = b / lambda_um;
  const double norm = 15.0 / (kPi * kPi * kPi * kPi) * b * b * b * b;
  const double l5 = lambda_um * lambda_um * lambda_um * lambda_um * lambda_um;
  return norm / (l5 * expm1(x));
}

// Wien's approximation with the same normalisation: e^-x in place of 1/(e^x - 1),
// x = c2 / (lambda T). Its relative error is exactly e^-x (it is the first term of
// Planck's series sum_n e^-(n x)): below 1% where lambda T < c2 / ln(100) = 3124 um K,
// e.g. lambda < 0.54 um for the Sun-like G2V (5770 K) but nowhere in the optical for
// an O5V star (41400 K: lambda < 0.075 um).
NEBULA_HD double wien_shape(double lambda_um, double T) {
  const double b = kC2 / T, x = b / lambda_um;
  const double norm = 15.0 / (kPi * kPi * kPi * kPi) * b * b * b * b;
  const double l5 = lambda_um * lambda_um * lambda_um * lambda_um * lambda_um;
  return norm * exp(-x) / l5;
}
// lambda T (um K) below which Wien's relative error is under `error`.
inline double wien_valid_below(double error) { return kC2 / -std::log(error); }

// A tabulated spectrum (e.g. a model atmosphere), linear between rows, zero
// outside them, normalised to integral 1 over its rows (so outside them it
// emits nothing: the table must cover the filters it is seen through).
struct TabulatedSpectrum {
  std::string name;
  std::vector<double> wavelength_um, shape;
  double operator()(double lambda_um) const;
};
// Two columns "wavelength_nm value" (spaces or a comma), '#' comments; the
// same checks as a filter file (one line naming the file, line and reason).
TabulatedSpectrum load_spectrum(const std::string& path);

}  // namespace nebula::spectral
