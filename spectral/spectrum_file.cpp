// Tabulated star spectra (spectral/spectra.h), read with the two-column
// reader of user filters (illumination/filter_file.h).
#include <filesystem>

#include "illumination/filter_file.h"
#include "spectral/spectra.h"

namespace nebula::spectral {

double TabulatedSpectrum::operator()(double lambda) const {
  if (wavelength_um.empty() || lambda < wavelength_um.front() || lambda > wavelength_um.back()) return 0.0;
  size_t i = 1;
  while (i + 1 < wavelength_um.size() && wavelength_um[i] < lambda) ++i;
  const double u = (lambda - wavelength_um[i - 1]) / (wavelength_um[i] - wavelength_um[i - 1]);
  return (1 - u) * shape[i - 1] + u * shape[i];
}

TabulatedSpectrum load_spectrum(const std::string& path) {
  const TwoColumns c = read_two_columns(path);
  TabulatedSpectrum s;
  s.name = std::filesystem::path(path).stem().string();
  double integral = 0.0;
  for (size_t i = 0; i < c.x.size(); ++i) {
    s.wavelength_um.push_back(c.x[i] / 1000.0);
    s.shape.push_back(c.y[i]);
    if (i > 0) integral += 0.5 * (c.y[i] + c.y[i - 1]) * (c.x[i] - c.x[i - 1]) / 1000.0;
  }
  for (double& v : s.shape) v /= integral;
  return s;
}

}  // namespace nebula::spectral
