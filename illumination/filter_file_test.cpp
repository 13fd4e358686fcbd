// User filter files (illumination/filter_file.h): two columns or the
// data/filters CSV; every bad file refused in one line naming file and reason.
#include "illumination/filter_file.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"

namespace nebula {
namespace {

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
}  // namespace nebula
