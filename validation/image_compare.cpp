#include "validation/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace nebula {
namespace {

void check_same(const Image& a, const Image& b, const std::string& a_name, const std::string& b_name) {
  if (a.width != b.width || a.height != b.height)
    throw Error(a_name + ": " + std::to_string(a.width) + "x" + std::to_string(a.height) + " pixels but " + b_name +
                " has " + std::to_string(b.width) + "x" + std::to_string(b.height));
  if (a.bands != b.bands) {
    std::string la, lb;
    for (const auto& s : a.bands) la += (la.empty() ? "" : ",") + s;
    for (const auto& s : b.bands) lb += (lb.empty() ? "" : ",") + s;
    throw Error(a_name + ": bands " + la + " but " + b_name + " has " + lb);
  }
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::floor(p * (v.size() - 1) + 0.5)));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// sRGB decode, so that the PNG writer's encode gives back `level`.
double srgb_decode(double e) { return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4); }

}  // namespace

Comparison compare_images(const Image& a, const Image& b, const Image* var_a, const Image* var_b,
                          double signal_fraction, const std::string& a_name, const std::string& b_name) {
  check_same(a, b, a_name, b_name);
  if (var_a) check_same(*var_a, a, a_name + " (variance)", a_name);
  if (var_b) check_same(*var_b, b, b_name + " (variance)", b_name);
  if (!(signal_fraction >= 0 && signal_fraction < 1)) throw ParameterError("signal_fraction", "must be in [0, 1)");
  Comparison out;
  out.signal_fraction = signal_fraction;
  const size_t n = a.plane_size();
  for (size_t band = 0; band < a.bands.size(); ++band) {
    BandComparison r;
    r.band = a.bands[band];
    const float* pa = a.pixels.data() + band * n;
    const float* pb = b.pixels.data() + band * n;
    double peak = 0;
    for (size_t i = 0; i < n; ++i) peak = std::max(peak, double(pb[i]));
    const double threshold = signal_fraction * peak;
    double l1 = 0, l2 = 0, ref1 = 0, ref2 = 0, signed_sum = 0, var_sum = 0, z2 = 0;
    size_t z_count = 0, beyond = 0;
    std::vector<double> rel;
    r.has_variance = var_a || var_b;
    for (size_t i = 0; i < n; ++i) {
      if (!(pb[i] > threshold) || !(pb[i] > 0)) continue;
      const double d = double(pa[i]) - pb[i];
      ++r.signal_pixels;
      l1 += std::fabs(d);
      l2 += d * d;
      ref1 += pb[i];
      ref2 += double(pb[i]) * pb[i];
      signed_sum += d;
      rel.push_back(std::fabs(d) / pb[i]);
      if (r.has_variance) {
        const double v = (var_a ? double(var_a->pixels[band * n + i]) : 0.0) +
                         (var_b ? double(var_b->pixels[band * n + i]) : 0.0);
        var_sum += v;
        if (v > 0) {
          z2 += d * d / v;
          ++z_count;
          beyond += d * d > 16 * v;
        }
      }
    }
    if (r.signal_pixels) {
      r.rel_l1 = l1 / ref1;
      r.rel_l2 = std::sqrt(l2 / ref2);
      r.worst_1pct = percentile(rel, 0.99);
      r.bias = signed_sum / ref1;
      if (r.has_variance) {
        r.noise_rel_l2 = std::sqrt(var_sum / ref2);
        r.bias_stderr = std::sqrt(var_sum) / ref1;
        r.rel_l2_excess = std::sqrt(std::max(0.0, l2 - var_sum) / ref2);
      }
    }
    if (z_count) {
      r.mean_z2 = z2 / z_count;
      r.beyond_4sigma = double(beyond) / z_count;
      r.within_noise = r.mean_z2 <= 1 + 4 * std::sqrt(2.0 / z_count);
    }
    out.bands.push_back(r);
  }
  return out;
}

std::string to_json(const Comparison& c) {
  std::string s = "{\"signal_fraction\": " + to_text(c.signal_fraction) + ", \"bands\": [";
  char buf[768];
  for (size_t i = 0; i < c.bands.size(); ++i) {
    const BandComparison& r = c.bands[i];
    std::snprintf(buf, sizeof buf,
                  "%s{\"band\": \"%s\", \"signal_pixels\": %zu, \"rel_l1\": %.9g, \"rel_l2\": %.9g, "
                  "\"worst_1pct\": %.9g, \"bias\": %.9g, \"bias_stderr\": %.9g, \"has_variance\": %s, \"noise_rel_l2\": %.9g, "
                  "\"rel_l2_excess\": %.9g, \"mean_z2\": %.9g, \"beyond_4sigma\": %.9g, \"within_noise\": %s}",
                  i ? ", " : "", r.band.c_str(), r.signal_pixels, r.rel_l1, r.rel_l2, r.worst_1pct, r.bias, r.bias_stderr,
                  r.has_variance ? "true" : "false", r.noise_rel_l2, r.rel_l2_excess, r.mean_z2, r.beyond_4sigma,
                  r.has_variance ? (r.within_noise ? "true" : "false") : "null");
    s += buf;
  }
  return s + "]}";
}

Image difference_picture(const Image& a, const Image& b, double signal_fraction, std::vector<double>* ranges) {
  check_same(a, b, "A", "B");
  const size_t n = a.plane_size();
  const int nb = static_cast<int>(a.bands.size());
  Image out(a.width * nb, a.height, {"B", "V", "R"});
  if (ranges) ranges->clear();
  for (int band = 0; band < nb; ++band) {
    const float* pa = a.pixels.data() + band * n;
    const float* pb = b.pixels.data() + band * n;
    double peak = 0;
    for (size_t i = 0; i < n; ++i) peak = std::max(peak, double(pb[i]));
    std::vector<double> diffs, all;
    for (size_t i = 0; i < n; ++i) {
      const double d = std::fabs(double(pa[i]) - pb[i]);
      all.push_back(d);
      if (pb[i] > signal_fraction * peak && pb[i] > 0) diffs.push_back(d);
    }
    double range = percentile(diffs.empty() ? all : diffs, 0.99);
    if (!(range > 0)) range = 1;
    if (ranges) ranges->push_back(range);
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        const double d = std::clamp((double(pa[y * a.width + x]) - pb[y * a.width + x]) / range, -1.0, 1.0);
        // White at 0; red (A brighter) or blue (A darker) as |d| grows.
        const double red = d >= 0 ? 1.0 : 1.0 + d, blue = d <= 0 ? 1.0 : 1.0 - d, green = 1.0 - std::fabs(d);
        const int px = band * a.width + x;
        out.at(0, px, y) = static_cast<float>(srgb_decode(blue));
        out.at(1, px, y) = static_cast<float>(srgb_decode(green));
        out.at(2, px, y) = static_cast<float>(srgb_decode(red));
      }
  }
  return out;
}

}  // namespace nebula
