#pragma once
#include <string>
#include <vector>

#include "illumination/passband.h"

namespace nebula {

// Physical constants, SI: the exact values of the 2019 SI (CODATA 2018).
constexpr double kPlanckConstant = 6.62607015e-34;  // h, J s
constexpr double kSpeedOfLight = 299792458.0;       // c, m/s
constexpr double kBoltzmannConstant = 1.380649e-23;  // k_B, J/K

// sigma = 2 pi^5 k^4 / (15 c^2 h^3), W m^-2 K^-4, from the constants above.
double stefan_boltzmann_constant();

// Effective temperature (K) of a main-sequence star from its spectral class:
// O5V, B0V, B5V, A0V, G2V or M0V, case-insensitive (Pecaut & Mamajek 2013,
// ApJS 208, 9; Mamajek's table v2024.05.15). Any other string is an Error
// listing the accepted classes.
double effective_temperature_K(const std::string& spectral_class);
std::vector<std::string> known_spectral_classes();  // hottest first

// Planck's black-body spectral radiance per unit wavelength,
// B_lambda(T) = 2 h c^2 / lambda^5 / (exp(h c / (lambda k T)) - 1),
// in W m^-2 sr^-1 m^-1, wavelength in m. T or lambda not positive and
// finite is an Error.
double planck_radiance(double wavelength_m, double temperature_K);

// integral over all wavelengths of B_lambda(T) = sigma T^4 / pi, W m^-2 sr^-1.
double planck_total_radiance(double temperature_K);

// The fraction of a black body's bolometric output that the passband passes:
// integral T_b(lambda) B_lambda(T) d lambda / integral B_lambda(T) d lambda
// (energy weighting, T_b peak-normalised as tabulated). A star of luminosity
// L emits Phi_b = L * fraction in band b.
double band_fraction(double temperature_K, const Passband& passband);

// band_fraction for each of `filters`, in their order.
std::vector<double> band_fractions(double temperature_K, const std::vector<Passband>& filters);

}  // namespace nebula
