#include "illumination/extinction.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"

namespace nebula {
namespace {

// Horner evaluation of c[0] + c[1] y + ... + c[n-1] y^(n-1).
template <size_t N>
double polynomial(const double (&c)[N], double y) {
  double sum = 0.0;
  for (size_t i = N; i-- > 0;) sum = sum * y + c[i];
  return sum;
}

// Optical polynomials in y = x - 1.82: CCM 1989 and O'Donnell 1994, the
// coefficients as listed in docs/references.md.
constexpr double kCcmA[] = {1.0,      0.17699, -0.50447, -0.02427,
                            0.72085,  0.01979, -0.77530, 0.32999};
constexpr double kCcmB[] = {0.0,     1.41338,  2.28305, 1.07233,
                            -5.38434, -0.62251, 5.30260, -2.09002};
constexpr double kODonnellA[] = {1.0,   0.104,  -0.609, 0.701, 1.137,
                                 -1.718, -0.827, 1.647, -0.505};
constexpr double kODonnellB[] = {0.0,    1.952, 2.908,   -3.989, -7.985,
                                 11.102, 5.491, -10.805, 3.347};

void check_R_V(double R_V) {
  if (!(R_V >= kMinRV && R_V <= kMaxRV))
    throw Error("R_V = " + to_text(R_V) + " is outside the extinction law's range [" +
                to_text(kMinRV) + ", " + to_text(kMaxRV) + "]");
}

}  // namespace

const char* to_string(ExtinctionLaw law) {
  switch (law) {
    case ExtinctionLaw::CCM89: return "CCM89";
    case ExtinctionLaw::ODonnell94: return "ODonnell94";
    case ExtinctionLaw::Grey: return "grey";
  }
  return "?";
}

ExtinctionCoefficients extinction_coefficients(double x, ExtinctionLaw law) {
  if (!(x >= kExtinctionMinInverseMicron && x <= kExtinctionMaxInverseMicron))
    throw Error("wavelength " + to_text(1000.0 / x) + " nm (x = " + to_text(x) +
                " 1/um) is outside the extinction law's range x in [" +
                to_text(kExtinctionMinInverseMicron) + ", " +
                to_text(kExtinctionMaxInverseMicron) + "] 1/um (" +
                to_text(1000.0 / kExtinctionMaxInverseMicron) + " to " +
                to_text(1000.0 / kExtinctionMinInverseMicron) + " nm)");
  if (x < 1.1) {
    const double power = std::pow(x, 1.61);  // CCM 1989 infrared power law
    return {0.574 * power, -0.527 * power};
  }
  if (x > 3.3) {  // CCM 1989 ultraviolet, with its far-UV curvature past x = 5.9
    const double fy = x > 5.9 ? x - 5.9 : 0.0;
    const double fa = -0.04473 * fy * fy - 0.009779 * fy * fy * fy;
    const double fb = 0.2130 * fy * fy + 0.1207 * fy * fy * fy;
    return {1.752 - 0.316 * x - 0.104 / ((x - 4.67) * (x - 4.67) + 0.341) + fa,
            -3.090 + 1.825 * x + 1.206 / ((x - 4.62) * (x - 4.62) + 0.263) + fb};
  }
  const double y = x - 1.82;
  if (law == ExtinctionLaw::ODonnell94) return {polynomial(kODonnellA, y), polynomial(kODonnellB, y)};
  return {polynomial(kCcmA, y), polynomial(kCcmB, y)};
}

double extinction_ratio_at(double wavelength_nm, double R_V, ExtinctionLaw law) {
  check_R_V(R_V);
  if (!(wavelength_nm > 0.0) || !std::isfinite(wavelength_nm))
    throw Error("wavelength " + to_text(wavelength_nm) + " nm is not a positive finite number");
  if (law == ExtinctionLaw::Grey) return 1.0;
  const ExtinctionCoefficients c = extinction_coefficients(1000.0 / wavelength_nm, law);
  return c.a + c.b / R_V;
}

double band_extinction_ratio(const Passband& passband, double R_V, ExtinctionLaw law,
                             const std::function<double(double)>* spectrum) {
  check_R_V(R_V);
  const auto source = [&](double lambda) { return spectrum ? (*spectrum)(lambda) : 1.0; };
  const double weight = passband_integral(passband, source, kPassbandSubdivisions);
  if (!(weight > 0.0))
    throw Error("passband '" + passband.name + "': the weight integral of T S is " +
                to_text(weight) + ", not positive");
  const double extinction = passband_integral(
      passband,
      [&](double lambda) { return source(lambda) * extinction_ratio_at(lambda, R_V, law); },
      kPassbandSubdivisions);
  return extinction / weight;
}

std::vector<double> extinction_ratios(const std::vector<Passband>& filters, const Passband& V, double R_V,
                                      ExtinctionLaw law, const std::function<double(double)>* spectrum) {
  const double v = band_extinction_ratio(V, R_V, law, spectrum);
  std::vector<double> out;
  for (const Passband& f : filters) out.push_back(band_extinction_ratio(f, R_V, law, spectrum) / v);
  return out;
}

}  // namespace nebula
