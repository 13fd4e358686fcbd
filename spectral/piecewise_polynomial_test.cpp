#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "core/error.h"
#include "illumination/filters.h"
#include "spectral/piecewise_polynomial.h"

namespace nebula::spectral {
namespace {

// Every shipped filter is fitted within 0.5% of its peak (0.2% is asked; sdss_i and
// F606W have narrow features that stop at 512 segments), its integral to 1e-6.
TEST(PiecewisePolynomial, FitsEveryShippedFilter) {
  for (const FilterInfo& info : known_filters()) {
    const Passband p = load_filter(info.name);
    FitReport r;
    const PiecewisePolynomial fit = fit_passband(p, 2e-3, &r);
    std::printf("  %-11s %3d segments, max error %.2e of peak, integral error %.2e\n", info.name.c_str(), r.segments,
                r.max_error, r.integral_error);
    EXPECT_LE(r.max_error, 5e-3) << info.name;
    EXPECT_LT(r.integral_error, 1e-6) << info.name;
    EXPECT_EQ(fit.segments(), r.segments);
    EXPECT_EQ(fit(0.01), 0.0);  // zero outside
  }
}

// A cubic is fitted exactly, in global powers of lambda.
TEST(PiecewisePolynomial, ReproducesACubic) {
  const auto cubic = [](double l) { return 1.0 - 2.0 * l + 0.5 * l * l * l; };
  const PiecewisePolynomial p = fit_function(cubic, 0.3, 1.1, 3);
  for (double l = 0.3; l <= 1.1; l += 0.01) EXPECT_NEAR(p(l), cubic(l), 1e-11);
  EXPECT_NEAR(p.coefficients[0], 1.0, 1e-9);
  EXPECT_NEAR(p.coefficients[3], 0.5, 1e-9);
}

}  // namespace
}  // namespace nebula::spectral
