#pragma once
#include <functional>
#include <vector>

#include "illumination/passband.h"

namespace nebula {

// A(lambda)/A(V) = a(x) + b(x)/R_V, x = 1/lambda in 1/um (Cardelli, Clayton &
// Mathis 1989, ApJ 345, 245). ODonnell94 replaces the optical polynomials
// (1.1 <= x < 3.3) by O'Donnell's (1994, ApJ 422, 158); the infrared is CCM's
// in both. Grey dust extinguishes every wavelength alike (A/A_V = 1), as
// radiative-transfer benchmarks at one wavelength assume; R_V plays no part.
enum class ExtinctionLaw { CCM89, ODonnell94, Grey };

const char* to_string(ExtinctionLaw law);

// The range of x covered here: infrared 0.3 <= x < 1.1, optical
// 1.1 <= x <= 3.3 (3.3 itself still optical) and CCM's ultraviolet
// 3.3 < x <= 8 (the filters of the spectral system reach 297 nm). Below
// x = 0.3 (3.33 to 5.3 um, JWST's F356W and F444W) CCM's infrared power law is
// extrapolated: CCM fitted it for 0.3 <= x only, and measured extinction
// there is flatter (docs/spectral.md states this).
constexpr double kExtinctionMinInverseMicron = 0.19;
constexpr double kExtinctionMaxInverseMicron = 8.0;
constexpr double kExtinctionFittedMinInverseMicron = 0.3;  // below: extrapolated
// R_V accepted: the law holds for R_V in about [2, 6] (docs/references.md).
constexpr double kMinRV = 2.0, kMaxRV = 6.0;

struct ExtinctionCoefficients {
  double a, b;  // A(lambda)/A(V) = a + b / R_V
};

// a(x) and b(x) at x in 1/um; an x outside [0.19, 8] is an Error naming it.
ExtinctionCoefficients extinction_coefficients(double x_inverse_micron, ExtinctionLaw law);

// A(lambda)/A(V) at one wavelength in nm. Errors name the wavelength and the
// valid range, or R_V outside [2, 6].
double extinction_ratio_at(double wavelength_nm, double R_V, ExtinctionLaw law);

// Band average of A/A_V:
//   integral T S A/A_V d lambda / integral T S d lambda,
// with S the source spectrum per unit wavelength (argument in nm; flat when
// null). Energy weighting: T multiplies the energy per unit wavelength, as the
// ray marcher carries energy per band. A photon-counting detector would weight
// by S lambda instead; pass that product as `spectrum` to get it.
double band_extinction_ratio(const Passband& passband, double R_V, ExtinctionLaw law,
                             const std::function<double(double)>* spectrum = nullptr);

// A_b/A_V for each of `filters` (tau_b = tau_v * (A_b/A_V), DESIGN.md section
// 3): each band average divided by the V filter's, so the V filter gives
// exactly 1 and tau_v is the extinction depth in the V passband.
std::vector<double> extinction_ratios(const std::vector<Passband>& filters, const Passband& V, double R_V,
                                      ExtinctionLaw law, const std::function<double(double)>* spectrum = nullptr);

}  // namespace nebula
