#include "illumination/filter_file.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace nebula {
namespace {
[[noreturn]] void refuse(const std::string& path, int line, const std::string& reason) {
  throw Error(path + ":" + std::to_string(line) + ": " + reason);
}
}  // namespace

TwoColumns read_two_columns(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open (missing or unreadable)");
  TwoColumns out;
  std::string text;
  bool any = false;
  for (int line = 1; std::getline(in, text); ++line) {
    const size_t hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    for (char& c : text)
      if (c == ',' || c == '\t' || c == '\r') c = ' ';
    std::istringstream cells(text);
    std::string a, b, extra;
    if (!(cells >> a)) continue;
    if (!(cells >> b) || (cells >> extra)) refuse(path, line, "expected two columns (wavelength_nm value)");
    char* end = nullptr;
    const double x = std::strtod(a.c_str(), &end);
    if (*end != '\0' || !std::isfinite(x)) refuse(path, line, "wavelength '" + a + "' is not a finite number");
    const double y = std::strtod(b.c_str(), &end);
    if (*end != '\0' || !std::isfinite(y)) refuse(path, line, "value '" + b + "' is not a finite number");
    if (!(x > 0.0)) refuse(path, line, "wavelength " + a + " nm is not positive");
    if (!out.x.empty() && !(x > out.x.back()))
      refuse(path, line, "wavelengths must be strictly ascending (" + a + " nm after " + to_text(out.x.back()) + ")");
    if (y < 0.0) refuse(path, line, "value " + b + " is negative");
    any = any || y > 0.0;
    out.x.push_back(x);
    out.y.push_back(y);
  }
  if (out.x.size() < 2) throw Error(path + ": needs at least 2 rows, found " + std::to_string(out.x.size()));
  if (!any) throw Error(path + ": every value is zero");
  return out;
}

Passband load_filter_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open filter file (missing or unreadable)");
  std::string text;
  while (std::getline(in, text)) {
    if (text.empty() || text[0] == '#') continue;
    if (text.rfind("wavelength_", 0) == 0) return load_passband(path);  // the data/filters CSV
    break;
  }
  const TwoColumns c = read_two_columns(path);
  Passband p;
  p.name = std::filesystem::path(path).stem().string();
  p.wavelength_nm = c.x;
  p.response = c.y;
  return p;
}

}  // namespace nebula
