#pragma once
// The display transform (PNG files and the viewer; never the science
// pixels of FITS, EXR or HDF5): radiance x exposure, divided by the white
// point, through a stretch (linear, asinh or log) to [0, 1], then the sRGB
// curve (imageio/tone_map.h). With auto exposure the exposure is chosen from
// the image: its `percentile`-th brightest value shows at the white point.
// docs/image_files.md and docs/scene.md ("[display]") give the formulas.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace nebula {

enum class Stretch { Linear, Asinh, Log };

inline const char* to_string(Stretch s) {
  return s == Stretch::Asinh ? "asinh" : s == Stretch::Log ? "log" : "linear";
}
inline bool parse_stretch(const std::string& name, Stretch& out) {
  for (Stretch s : {Stretch::Linear, Stretch::Asinh, Stretch::Log})
    if (name == to_string(s)) {
      out = s;
      return true;
    }
  return false;
}

struct DisplaySettings {
  Stretch stretch = Stretch::Linear;
  bool auto_exposure = false;
  double percentile = 99.5;  // auto exposure: this percentile of the non-zero values shows at the white point
  double white = 1.0;        // the exposed value shown as full white (> 0)
  double softening = 0.02;   // asinh and log: where, as a fraction of white, the curve turns from linear to log (> 0)
  bool operator==(const DisplaySettings& o) const {
    return stretch == o.stretch && auto_exposure == o.auto_exposure && percentile == o.percentile &&
           white == o.white && softening == o.softening;
  }
};

// The stretched value in [0, 1] of an exposed value x >= 0 (x = radiance x exposure).
// linear: x / white; asinh: asinh(x / (s w)) / asinh(1 / s); log: ln(1 + x / (s w)) / ln(1 + 1 / s);
// each 0 at 0 and 1 at the white point, clamped to [0, 1]; NaN shows as 0.
inline double stretch_value(double x, const DisplaySettings& d) {
  if (!(x > 0)) return 0.0;
  const double r = x / d.white;
  double y = r;
  if (d.stretch == Stretch::Asinh)
    y = std::asinh(r / d.softening) / std::asinh(1.0 / d.softening);
  else if (d.stretch == Stretch::Log)
    y = std::log1p(r / d.softening) / std::log1p(1.0 / d.softening);
  return std::min(y, 1.0);
}

// The exposure auto exposure picks: white / (the percentile of the finite,
// positive values), or `fallback` when there are none.
inline double auto_exposure_of(const std::vector<float>& values, const DisplaySettings& d, double fallback) {
  std::vector<float> positive;
  positive.reserve(values.size());
  for (float v : values)
    if (v > 0 && std::isfinite(v)) positive.push_back(v);
  if (positive.empty()) return fallback;
  const double q = std::clamp(d.percentile, 0.0, 100.0) / 100.0;
  const size_t k = std::min(positive.size() - 1, size_t(q * double(positive.size() - 1) + 0.5));
  std::nth_element(positive.begin(), positive.begin() + std::ptrdiff_t(k), positive.end());
  return d.white / double(positive[k]);
}

}  // namespace nebula
