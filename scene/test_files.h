#pragma once
// Test helpers for scene/: a fresh temporary folder per test (core/test_support.h),
// and writers of small HDF5 and FITS grids through the libraries' C APIs.
#include <fitsio.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/test_support.h"

namespace nebula::testing {

namespace fs = std::filesystem;

class TempDirTest : public ::testing::Test, protected ScratchDir {
 protected:
  TempDirTest() : ScratchDir("nebula_scene") {}

  std::string write_text(const std::string& name, const std::string& text) const {
    const std::string p = path(name);
    fs::create_directories(fs::path(p).parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

struct H5Dataset {
  std::string name = "tau_v";
  std::vector<hsize_t> dims;  // [nz][ny][nx]
  std::vector<double> values;  // written in `file_type`; empty: the dataset is created, not written
  hid_t file_type = H5T_IEEE_F32LE;
  std::optional<double> voxel_size;        // attribute on the dataset
  std::optional<std::vector<double>> origin;  // attribute on the dataset
};

// Writes datasets (and optional root attributes) to a new HDF5 file.
inline void write_h5(const std::string& path, const std::vector<H5Dataset>& sets,
                     std::optional<double> root_voxel_size = std::nullopt) {
  fs::create_directories(fs::path(path).parent_path());
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  auto attribute = [](hid_t holder, const char* name, const std::vector<double>& v) {
    const hsize_t n = v.size();
    const hid_t space = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
    const hid_t attr = H5Acreate2(holder, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, H5T_NATIVE_DOUBLE, v.data());
    H5Aclose(attr);
    H5Sclose(space);
  };
  for (const H5Dataset& s : sets) {
    const hid_t space = H5Screate_simple(int(s.dims.size()), s.dims.data(), nullptr);
    const hid_t set =
        H5Dcreate2(file, s.name.c_str(), s.file_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(set, 0);
    if (!s.values.empty()) {
      ASSERT_GE(H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.values.data()), 0);
    }
    if (s.voxel_size) attribute(set, "voxel_size", {*s.voxel_size});
    if (s.origin) attribute(set, "origin", *s.origin);
    H5Dclose(set);
    H5Sclose(space);
  }
  if (root_voxel_size) attribute(file, "voxel_size", {*root_voxel_size});
  H5Fclose(file);
}

// A 3D FITS primary image nx x ny x nz (NAXIS1 = nx) of `bitpix`, values in
// file order (x fastest), with extra keywords (numbers or strings).
struct FitsKeys {
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> strings;
  std::map<std::string, long> integers;
};

inline void write_fits(const std::string& path, std::vector<long> naxes,
                       const std::vector<double>& values, int bitpix, const FitsKeys& keys) {
  fs::remove(path);
  fitsfile* f = nullptr;
  int status = 0;
  fits_create_diskfile(&f, path.c_str(), &status);
  ASSERT_EQ(status, 0);
  fits_create_img(f, bitpix, int(naxes.size()), naxes.data(), &status);
  for (const auto& [k, v] : keys.numbers) {
    double value = v;
    fits_update_key(f, TDOUBLE, k.c_str(), &value, nullptr, &status);
  }
  for (const auto& [k, v] : keys.integers) {
    long value = v;
    fits_update_key(f, TLONG, k.c_str(), &value, nullptr, &status);
  }
  for (const auto& [k, v] : keys.strings)
    fits_update_key(f, TSTRING, k.c_str(), const_cast<char*>(v.c_str()), nullptr, &status);
  fits_set_bscale(f, 1.0, 0.0, &status);  // write raw values; BSCALE/BZERO apply on reading
  if (!values.empty()) {
    std::vector<double> copy = values;
    fits_write_img(f, TDOUBLE, 1, LONGLONG(copy.size()), copy.data(), &status);
  }
  fits_close_file(f, &status);
  ASSERT_EQ(status, 0);
}

}  // namespace nebula::testing
