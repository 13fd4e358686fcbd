#include "illumination/star.h"

#include <cctype>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/math.h"

namespace nebula {
namespace {

struct ClassTemperature {
  const char* spectral_class;
  double temperature_K;
};

// Pecaut & Mamajek 2013 (ApJS 208, 9), Mamajek's table v2024.05.15, as
// listed in docs/references.md.
constexpr ClassTemperature kDwarfTemperatures[] = {
    {"O5V", 41400.0}, {"B0V", 31400.0}, {"B5V", 15700.0},
    {"A0V", 9700.0},  {"G2V", 5770.0},  {"M0V", 3850.0},
};

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

void check_temperature(double temperature_K) {
  if (!(temperature_K > 0.0) || !std::isfinite(temperature_K))
    throw Error("temperature T = " + number(temperature_K) + " K must be positive and finite");
}

std::string upper(const std::string& s) {
  std::string out = s;
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

double stefan_boltzmann_constant() {
  const double k = kBoltzmannConstant, c = kSpeedOfLight, h = kPlanckConstant;
  return 2.0 * std::pow(kPiD, 5) * std::pow(k, 4) / (15.0 * c * c * h * h * h);
}

std::vector<std::string> known_spectral_classes() {
  std::vector<std::string> names;
  for (const ClassTemperature& entry : kDwarfTemperatures) names.push_back(entry.spectral_class);
  return names;
}

double effective_temperature_K(const std::string& spectral_class) {
  const std::string wanted = upper(spectral_class);
  for (const ClassTemperature& entry : kDwarfTemperatures)
    if (wanted == entry.spectral_class) return entry.temperature_K;
  std::string accepted;
  for (const std::string& name : known_spectral_classes())
    accepted += (accepted.empty() ? "" : ", ") + name;
  throw Error("unknown spectral class '" + spectral_class + "': accepted are " + accepted);
}

double planck_radiance(double wavelength_m, double temperature_K) {
  check_temperature(temperature_K);
  if (!(wavelength_m > 0.0) || !std::isfinite(wavelength_m))
    throw Error("wavelength " + number(wavelength_m) + " m must be positive and finite");
  const double h = kPlanckConstant, c = kSpeedOfLight;
  const double exponent = h * c / (wavelength_m * kBoltzmannConstant * temperature_K);
  // expm1 keeps the Rayleigh-Jeans end accurate; a huge exponent gives inf
  // and the radiance 0, which is its limit.
  return 2.0 * h * c * c / std::pow(wavelength_m, 5) / std::expm1(exponent);
}

double planck_total_radiance(double temperature_K) {
  check_temperature(temperature_K);
  return stefan_boltzmann_constant() * std::pow(temperature_K, 4) / kPiD;
}

double band_fraction(double temperature_K, const Passband& passband) {
  const double total = planck_total_radiance(temperature_K);  // checks T
  // Passband wavelengths are in nm: B_lambda per metre times d lambda in nm
  // times 1e-9 m/nm.
  const double in_band = passband_integral(
      passband, [&](double lambda_nm) { return planck_radiance(lambda_nm * 1e-9, temperature_K); },
      kPassbandSubdivisions);
  return in_band * 1e-9 / total;
}

std::vector<double> band_fractions(double temperature_K, const std::vector<Passband>& filters) {
  std::vector<double> out;
  for (const Passband& f : filters) out.push_back(band_fraction(temperature_K, f));
  return out;
}

}  // namespace nebula
