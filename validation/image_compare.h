#pragma once
// Image against reference (DESIGN.md section 5, "Accuracy"): the metrics of
// `nebula compare` and of the accuracy reports (docs/accuracy.md).
#include <string>
#include <vector>

#include "core/image.h"

namespace nebula {

struct BandComparison {
  std::string band;
  size_t signal_pixels = 0;   // pixels where the reference exceeds signal_fraction x its peak
  double rel_l1 = 0;          // sum |A - B| / sum |B| over signal pixels
  double rel_l2 = 0;          // sqrt(sum (A - B)^2 / sum B^2)
  double worst_1pct = 0;      // 99th percentile of |A - B| / B over signal pixels
  double bias = 0;            // sum (A - B) / sum B (mean signed error, relative)
  double bias_stderr = 0;     // its standard error from the variance images: sqrt(sum var) / sum B
  // With variance images (B's, plus A's when it has one):
  bool has_variance = false;
  double noise_rel_l2 = 0;    // sqrt(sum var / sum B^2): the L2 error noise alone would give
  double rel_l2_excess = 0;   // sqrt(max(0, sum (A-B)^2 - sum var) / sum B^2): the error beyond the noise
  double mean_z2 = 0;         // mean of (A - B)^2 / var over signal pixels with var > 0
  double beyond_4sigma = 0;   // fraction of those pixels with |A - B| > 4 sigma
  bool within_noise = false;  // mean_z2 <= 1 + 4 sqrt(2 / n): a 4-sigma chi-square bound
};

struct Comparison {
  std::vector<BandComparison> bands;
  double signal_fraction = 1e-3;
};

// A against reference B, per band. var_b (and var_a) are variance images of
// the pixel means, or null. Throws Error when sizes or band names differ
// (names the `a_name`/`b_name` given).
Comparison compare_images(const Image& a, const Image& b, const Image* var_a, const Image* var_b,
                          double signal_fraction = 1e-3, const std::string& a_name = "A",
                          const std::string& b_name = "B");

// One line of JSON.
std::string to_json(const Comparison& c);

// A false-colour picture of A - B: one panel per band side by side, white
// where they agree, red where A is brighter, blue where it is darker, full
// colour at +-`range` (returned: the 99th percentile of |A - B| over the
// band's signal pixels, or of all pixels when it has none). Bands B, V, R
// so that write_image writes it as an sRGB PNG with exposure 1.
Image difference_picture(const Image& a, const Image& b, double signal_fraction, std::vector<double>* ranges);

}  // namespace nebula
