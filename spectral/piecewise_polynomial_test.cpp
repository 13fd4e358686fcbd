#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "core/error.h"
#include "illumination/filters.h"
#include "spectral/piecewise_polynomial.h"
#include "spectral/two_column_file.h"

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

std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

void refused(const std::string& name, const std::string& text, const std::string& reason) {
  const std::string path = write(name, text);
  try {
    load_filter_file(path);
    ADD_FAILURE() << name << " was accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find(reason), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(FilterFile, ReadsTwoColumnsAndRefusesBadOnes) {
  const Passband p = load_filter_file(write("ha.dat", "# H-alpha\n650 0\n655, 0.9\n656.3\t1.0\n660 0\n"));
  EXPECT_EQ(p.wavelength_nm.size(), 4u);
  EXPECT_DOUBLE_EQ(p.wavelength_nm[2], 656.3);
  refused("neg.dat", "650 0\n-655 1\n", "not positive");
  refused("unsorted.dat", "650 0\n660 1\n655 1\n", "strictly ascending");
  refused("negative_value.dat", "650 0\n660 -1\n", "negative");
  refused("three.dat", "650 0 1\n", "two columns");
  refused("word.dat", "650 zero\n", "not a finite number");
  refused("zero.dat", "650 0\n660 0\n", "zero");
  refused("one_row.dat", "650 1\n", "at least 2 rows");
  // The data/filters CSV form is read by its own loader.
  EXPECT_EQ(load_filter_file(write("v.csv", "wavelength_nm,response\n500,0\n550,1\n600,0\n")).response[1], 1.0);
}

}  // namespace
}  // namespace nebula::spectral
