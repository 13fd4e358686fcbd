#include "illumination/passband.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "core/error.h"
#include "illumination/data_dir.h"

namespace nebula {
namespace {

std::string_view trimmed(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> cells_of(std::string_view line) {
  std::vector<std::string_view> cells;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    cells.push_back(trimmed(line.substr(start, comma == std::string_view::npos ? comma : comma - start)));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

[[noreturn]] void refuse(const std::string& path, int line, const std::string& reason) {
  throw Error(path + ":" + std::to_string(line) + ": " + reason);
}

double parse_number(std::string_view cell, const char* column, const std::string& path, int line) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (cell.empty() || error != std::errc() || end != cell.data() + cell.size())
    refuse(path, line, std::string(column) + " '" + std::string(cell) + "' is not a number");
  if (!std::isfinite(value))
    refuse(path, line, std::string(column) + " '" + std::string(cell) + "' is not finite");
  return value;
}

}  // namespace

Passband load_passband(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open passband file (missing or unreadable)");

  Passband band;
  band.name = std::filesystem::path(path).stem().string();
  double nm_per_unit = 0.0;  // set by the header
  int header_line = 0;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    const std::string_view content = trimmed(text);
    if (content.empty() || content.front() == '#') continue;
    const std::vector<std::string_view> cells = cells_of(content);
    if (nm_per_unit == 0.0) {
      if (cells.size() == 2 && cells[0] == "wavelength_angstrom" && cells[1] == "response") {
        nm_per_unit = 0.1;
      } else if (cells.size() == 2 && cells[0] == "wavelength_nm" && cells[1] == "response") {
        nm_per_unit = 1.0;
      } else {
        refuse(path, line, "expected the header 'wavelength_angstrom,response' or "
                           "'wavelength_nm,response', found '" + std::string(content) + "'");
      }
      header_line = line;
      continue;
    }
    if (cells.size() != 2)
      refuse(path, line, "expected 2 cells (wavelength,response), found " +
                             std::to_string(cells.size()));
    const double wavelength = parse_number(cells[0], "wavelength", path, line) * nm_per_unit;
    const double response = parse_number(cells[1], "response", path, line);
    if (!(wavelength > 0.0)) refuse(path, line, "wavelength must be positive");
    if (!band.wavelength_nm.empty() && !(wavelength > band.wavelength_nm.back()))
      refuse(path, line, "wavelengths must be strictly ascending");
    if (response < 0.0) refuse(path, line, "response must not be negative");
    band.wavelength_nm.push_back(wavelength);
    band.response.push_back(response);
  }
  if (header_line == 0) throw Error(path + ": no header line 'wavelength_angstrom,response'");
  if (band.wavelength_nm.size() < 2)
    throw Error(path + ": a passband needs at least 2 rows, found " +
                std::to_string(band.wavelength_nm.size()));
  bool any_response = false;
  for (double r : band.response) any_response = any_response || r > 0.0;
  if (!any_response) throw Error(path + ": response is zero at every wavelength");
  return band;
}

double passband_integral(const Passband& passband, const std::function<double(double)>& f,
                         int subdivisions) {
  if (subdivisions < 1)
    throw Error("passband_integral: subdivisions must be at least 1, got " +
                std::to_string(subdivisions));
  const std::vector<double>& x = passband.wavelength_nm;
  const std::vector<double>& t = passband.response;
  double sum = 0.0;
  for (size_t i = 0; i + 1 < x.size(); ++i) {
    if (t[i] == 0.0 && t[i + 1] == 0.0) continue;  // nothing passes: f is not evaluated
    const double step = (x[i + 1] - x[i]) / subdivisions;
    // T f at the step's ends; a node where T = 0 contributes nothing, so f is
    // not evaluated there (f may be undefined just outside the band).
    const auto weighted = [&](int k) {
      const double u = static_cast<double>(k) / subdivisions;
      const double response = (1.0 - u) * t[i] + u * t[i + 1];
      if (response == 0.0) return 0.0;
      const double wavelength = k == subdivisions ? x[i + 1] : x[i] + k * step;
      return response * f(wavelength);
    };
    double previous = weighted(0);
    for (int k = 1; k <= subdivisions; ++k) {
      const double next = weighted(k);
      sum += 0.5 * step * (previous + next);
      previous = next;
    }
  }
  return sum;
}

double mean_wavelength_nm(const Passband& passband) {
  const double weight = passband_integral(passband, [](double) { return 1.0; }, 1);
  if (!(weight > 0.0)) throw Error("passband '" + passband.name + "' has no response");
  return passband_integral(passband, [](double lambda) { return lambda; }, 1) / weight;
}

}  // namespace nebula
