#pragma once
#include <functional>
#include <string>
#include <vector>

namespace nebula {

// A photometric passband: the relative response T(lambda), linear between the
// tabulated wavelengths and zero outside them. Wavelengths are in nm
// (ascending), the response is dimensionless and never negative.
struct Passband {
  std::string name;  // the file's stem, e.g. "bessell-V"
  std::vector<double> wavelength_nm, response;
};

// Reads a CSV passband (format: data/filters/README.md): '#' comment lines,
// a header "wavelength_angstrom,response" or "wavelength_nm,response", then
// one row per wavelength. Refuses a missing file, a bad header, non-numeric
// or non-finite cells, wavelengths that are not positive and strictly
// ascending, a negative response, a response that is zero everywhere and
// fewer than 2 rows; the Error names the file and line.
Passband load_passband(const std::string& path);

// The integral of T(lambda) f(lambda) d lambda over the passband (lambda in
// nm, so the result carries a factor nm). Each tabulated interval is cut into
// `subdivisions` equal steps with T linear on it, and the product is
// integrated by the trapezoid rule; subdivisions = 1 is the plain trapezoid
// rule on the tabulated wavelengths. f is evaluated only where T > 0, so it
// may be undefined where the response has fallen to zero.
double passband_integral(const Passband& passband, const std::function<double(double)>& f,
                         int subdivisions);

// Steps per tabulated interval used for smooth weights (extinction laws,
// black bodies): with Bessell's 10 and 50 nm intervals, 128 keeps band
// averages within about 1e-7 of their converged values (tests compare with
// 1024 and allow 1e-6).
constexpr int kPassbandSubdivisions = 128;

// Mean wavelength (nm): integral lambda T / integral T, trapezoid rule on the
// tabulated wavelengths (the definition quoted with Bessell's means).
double mean_wavelength_nm(const Passband& passband);

}  // namespace nebula
