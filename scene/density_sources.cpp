#include "scene/density_sources.h"

#include <fitsio.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <string>

#include "core/error.h"
#include "core/memory.h"
#include "hdf5io/hdf5_support.h"

namespace nebula {
namespace {

// cfitsio (unless built reentrant) must not be entered from two threads at
// once; HDF5 has the program-wide hdf5io::hdf5_mutex().
std::mutex& fits_lock() {
  static std::mutex m;
  return m;
}


// Fails early, with the system's reason, when the file cannot be read.
void require_readable(const std::string& path) {
  std::ifstream probe(path, std::ios::binary);
  if (!probe) {
    const int err = errno;
    throw Error(path + ": cannot open (" + std::strerror(err ? err : ENOENT) + ")");
  }
}

// ---------------------------------------------------------------- HDF5

using hdf5io::Handle;

// The object (dataset or root group) that carries `name`, or -1.
hid_t attribute_holder(hid_t dataset, hid_t file, const char* name) {
  if (H5Aexists(dataset, name) > 0) return dataset;
  if (H5Aexists_by_name(file, "/", name, H5P_DEFAULT) > 0) return file;
  return -1;
}

// Reads a numeric attribute of exactly `count` elements as doubles.
std::vector<double> read_numeric_attribute(hid_t holder, const char* name, size_t count,
                                           const std::string& what) {
  Handle attr(H5Aopen(holder, name, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) throw Error(what + ": cannot open attribute '" + name + "'");
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER)
    throw Error(what + ": attribute '" + name + "' must be numeric");
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n != static_cast<hssize_t>(count))
    throw Error(what + ": attribute '" + name + "' must have " + std::to_string(count) +
                (count == 1 ? " value" : " values") + ", found " + std::to_string(n));
  std::vector<double> values(count);
  if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data()) < 0)
    throw Error(what + ": cannot read attribute '" + name + "'");
  return values;
}

std::string root_names(hid_t file) {
  std::string names;
  auto add = [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
    std::string& list = *static_cast<std::string*>(out);
    list += (list.empty() ? "" : ", ") + std::string(name);
    return 0;
  };
  H5Literate(file, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, add, &names);
  return names.empty() ? "none" : names;
}

struct Hdf5Grid {
  GridShape shape;
  bool has_voxel = false;
  std::vector<float> values;
};

// What a caller requires of a grid, checked before its values are allocated
// (cheap checks first: a small file may claim a huge grid).
struct GridNeeds {
  int rank = 3;
  bool voxel_size = false;                // a density: the attribute must be there
  const GridShape* shape = nullptr;       // an emission grid: the density's shape
};

// Opens `path`, checks `dataset` is a numeric array of the wanted rank that
// fits in memory, reads voxel_size/origin when present and the values as float.
Hdf5Grid read_hdf5_grid_here(const std::string& path, const std::string& dataset, const GridNeeds& needs) {
  const int want_rank = needs.rank;
  require_readable(path);
  const std::string what = path + ": dataset '" + dataset + "'";
  std::lock_guard<std::mutex> lock(hdf5io::hdf5_mutex());
  hdf5io::silence_hdf5_errors();
  if (H5Fis_hdf5(path.c_str()) <= 0) throw Error(path + ": not an HDF5 file");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) throw Error(path + ": cannot open as HDF5");
  if (dataset.empty() || H5Lexists(file.get(), dataset.c_str(), H5P_DEFAULT) <= 0)
    throw Error(what + " not found (the file holds: " + root_names(file.get()) + ")");
  Handle set(H5Dopen2(file.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) throw Error(what + ": not a dataset");
  Handle type(H5Dget_type(set.get()), H5Tclose);
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER)
    throw Error(what + ": must hold numbers (float or integer)");
  Handle space(H5Dget_space(set.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank != want_rank)
    throw Error(what + (want_rank == 3 ? ": must be 3-D [nz][ny][nx], found " : ": must be 2-D [nr][nx], found ") +
                std::to_string(rank) + "-D");
  hsize_t dims[3] = {1, 0, 0};
  H5Sget_simple_extent_dims(space.get(), want_rank == 3 ? dims : dims + 1, nullptr);
  check_grid_size(what, dims[2], dims[1], dims[0]);
  if (dims[0] > uint64_t(std::numeric_limits<int>::max()) ||
      dims[1] > uint64_t(std::numeric_limits<int>::max()) ||
      dims[2] > uint64_t(std::numeric_limits<int>::max()))
    throw Error(what + ": a size exceeds " + std::to_string(std::numeric_limits<int>::max()));

  Hdf5Grid grid;
  grid.shape.nx = static_cast<int>(dims[2]);
  grid.shape.ny = static_cast<int>(dims[1]);
  grid.shape.nz = static_cast<int>(dims[0]);
  if (const GridShape* want = needs.shape;
      want && (grid.shape.nx != want->nx || grid.shape.ny != want->ny || grid.shape.nz != want->nz))
    throw Error(what + ": shape " + std::to_string(grid.shape.nx) + " x " + std::to_string(grid.shape.ny) + " x " +
                std::to_string(grid.shape.nz) + " (nx x ny x nz) differs from the density's " +
                std::to_string(want->nx) + " x " + std::to_string(want->ny) + " x " + std::to_string(want->nz));
  const hid_t voxel_holder = attribute_holder(set.get(), file.get(), "voxel_size");
  if (voxel_holder >= 0) {
    const double voxel = read_numeric_attribute(voxel_holder, "voxel_size", 1, what)[0];
    if (!(voxel > 0) || !std::isfinite(voxel) || !(static_cast<float>(voxel) > 0) ||
        !std::isfinite(static_cast<float>(voxel)))
      throw Error(what + ": attribute 'voxel_size' = " + to_text(voxel) +
                  " must be positive and finite (the voxel edge in parsecs)");
    grid.shape.voxel = static_cast<float>(voxel);
    grid.has_voxel = true;
  } else if (needs.voxel_size) {
    throw Error(what + ": missing attribute 'voxel_size' (the voxel edge in parsecs) on the dataset or the file");
  }
  const hid_t origin_holder = attribute_holder(set.get(), file.get(), "origin");
  if (origin_holder >= 0) {
    const std::vector<double> o = read_numeric_attribute(origin_holder, "origin", 3, what);
    for (double v : o)
      if (!std::isfinite(v) || std::fabs(v) > 1e30)
        throw Error(what + ": attribute 'origin' has a non-finite value " + to_text(v));
    grid.shape.origin = Vec3{float(o[0]), float(o[1]), float(o[2])};
  }
  // Values the file does not hold: never written, or a contiguous dataset
  // whose bytes lie (partly) beyond the end of a truncated file.
  H5D_space_status_t allocated = H5D_SPACE_STATUS_ERROR;
  if (H5Dget_space_status(set.get(), &allocated) < 0 || allocated == H5D_SPACE_STATUS_NOT_ALLOCATED)
    throw Error(what + ": holds no values (the dataset was created but never written)");
  {
    Handle create(H5Dget_create_plist(set.get()), H5Pclose);
    const size_t element = H5Tget_size(type.get());
    if (create.valid() && H5Pget_layout(create.get()) == H5D_CONTIGUOUS && element > 0) {
      const haddr_t offset = H5Dget_offset(set.get());
      const long double need = static_cast<long double>(grid.shape.count()) * element;
      std::error_code ec;
      const auto file_bytes = std::filesystem::file_size(path, ec);
      if (!ec && offset != HADDR_UNDEF && static_cast<long double>(offset) + need > file_bytes)
        throw Error(what + ": its values need " + bytes_text(double(need)) + " but the file ends after " +
                    bytes_text(double(file_bytes)) + " (truncated?)");
    }
  }
  try {
    grid.values.resize(grid.shape.count());
  } catch (const std::bad_alloc&) {
    throw Error(what + ": out of memory allocating " +
                bytes_text(double(grid.shape.count()) * sizeof(float)));
  }
  if (H5Dread(set.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, grid.values.data()) < 0)
    throw Error(what + ": cannot read the values");
  return grid;
}

// A user's file: read in a child first, which survives libhdf5's crashes.
Hdf5Grid read_hdf5_grid(const std::string& path, const std::string& dataset, const GridNeeds& needs = {}) {
  hdf5io::read_in_child_first(path, [&] { read_hdf5_grid_here(path, dataset, needs); });
  return read_hdf5_grid_here(path, dataset, needs);
}

// ---------------------------------------------------------------- FITS

std::string fits_reason(int status) {
  char text[FLEN_STATUS] = {0};
  fits_get_errstatus(status, text);
  fits_clear_errmsg();
  return text;
}

// A keyword's value, or nothing when the header lacks it.
bool fits_double_key(fitsfile* f, const std::string& key, double& value, const std::string& what) {
  int status = 0;
  fits_read_key(f, TDOUBLE, key.c_str(), &value, nullptr, &status);
  if (status == KEY_NO_EXIST) {
    fits_clear_errmsg();
    return false;
  }
  if (status != 0)
    throw Error(what + ": keyword " + key + " is not a number (" + fits_reason(status) + ")");
  if (!std::isfinite(value)) throw Error(what + ": keyword " + key + " = " + to_text(value) + " is not finite");
  return true;
}

bool fits_string_key(fitsfile* f, const std::string& key, std::string& value) {
  int status = 0;
  char text[FLEN_VALUE] = {0};
  fits_read_key(f, TSTRING, key.c_str(), text, nullptr, &status);
  if (status != 0) {
    fits_clear_errmsg();
    return false;
  }
  value = text;
  return true;
}

std::string trimmed_lower(std::string s) {
  while (!s.empty() && s.back() == ' ') s.pop_back();
  size_t b = 0;
  while (b < s.size() && s[b] == ' ') ++b;
  s = s.substr(b);
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

// ---------------------------------------------------------------- checks

size_t grid_memory_limit_bytes() { return memory_limit_bytes(); }

void check_grid_size(const std::string& what, uint64_t nx, uint64_t ny, uint64_t nz,
                     uint64_t bytes_per_voxel, uint64_t limit_bytes) {
  const std::string dims = std::to_string(nx) + " x " + std::to_string(ny) + " x " +
                           std::to_string(nz) + " (nx x ny x nz)";
  if (nx == 0 || ny == 0 || nz == 0) throw Error(what + ": the grid has a zero size, " + dims);
  // In long double the product cannot overflow; it only has to compare.
  const long double bytes =
      static_cast<long double>(nx) * ny * nz * static_cast<long double>(bytes_per_voxel);
  if (bytes > static_cast<long double>(limit_bytes))
    throw Error(what + ": a grid of " + dims + " voxels needs " + bytes_text(double(bytes)) +
                ", more than the limit of " + bytes_text(double(limit_bytes)) +
                " (half the physical memory)");
}

void check_grid_values(const std::string& what, const GridShape& shape,
                       const std::vector<float>& values, const char* quantity) {
  if (values.size() != shape.count())
    throw Error(what + ": holds " + std::to_string(values.size()) + " values for " +
                std::to_string(shape.count()) + " voxels");
  for (size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    if (std::isfinite(v) && v >= 0.0f) continue;
    const size_t x = i % size_t(shape.nx), y = (i / size_t(shape.nx)) % size_t(shape.ny),
                 z = i / (size_t(shape.nx) * size_t(shape.ny));
    throw Error(what + ": voxel (x=" + std::to_string(x) + ", y=" + std::to_string(y) +
                ", z=" + std::to_string(z) + ") (index " + std::to_string(i) + ") is " +
                to_text(v) + "; " + quantity + " must be finite and >= 0");
  }
}

// ---------------------------------------------------------------- loaders

DensityGrid load_density_hdf5(const std::string& path, const std::string& dataset) {
  GridNeeds needs;
  needs.voxel_size = true;
  Hdf5Grid grid = read_hdf5_grid(path, dataset, needs);
  const std::string what = path + ": dataset '" + dataset + "'";
  if (!grid.has_voxel)
    throw Error(what + ": missing attribute 'voxel_size' (the voxel edge in parsecs) on the "
                       "dataset or the file");
  check_grid_values(what, grid.shape, grid.values);
  return DensityGrid{grid.shape, std::move(grid.values)};
}

std::vector<float> load_emission_hdf5(const std::string& path, const std::string& dataset,
                                      const GridShape& density_shape) {
  GridNeeds needs;
  needs.shape = &density_shape;
  Hdf5Grid grid = read_hdf5_grid(path, dataset, needs);
  const std::string what = path + ": dataset '" + dataset + "'";
  const GridShape& s = grid.shape;
  if (s.nx != density_shape.nx || s.ny != density_shape.ny || s.nz != density_shape.nz)
    throw Error(what + ": shape " + std::to_string(s.nx) + " x " + std::to_string(s.ny) + " x " +
                std::to_string(s.nz) + " (nx x ny x nz) differs from the density's " +
                std::to_string(density_shape.nx) + " x " + std::to_string(density_shape.ny) +
                " x " + std::to_string(density_shape.nz));
  if (grid.has_voxel &&
      std::fabs(double(s.voxel) - density_shape.voxel) > 1e-6 * double(density_shape.voxel))
    throw Error(what + ": voxel_size " + to_text(s.voxel) + " differs from the density's " +
                to_text(density_shape.voxel));
  check_grid_values(what, density_shape, grid.values, "emission");
  return std::move(grid.values);
}

std::vector<float> load_axial_plane_hdf5(const std::string& path, const std::string& dataset, int& nx, int& nr,
                                         const char* quantity) {
  GridNeeds needs;
  needs.rank = 2;
  Hdf5Grid grid = read_hdf5_grid(path, dataset, needs);
  const std::string what = path + ": dataset '" + dataset + "'";
  check_grid_values(what, grid.shape, grid.values, quantity);
  nx = grid.shape.nx;
  nr = grid.shape.ny;
  return std::move(grid.values);
}

DensityGrid load_density_fits(const std::string& path, double voxel_size_pc) {
  require_readable(path);
  const std::string what = path + ": primary image";
  std::lock_guard<std::mutex> lock(fits_lock());
  fitsfile* f = nullptr;
  int status = 0;
  // The disk-file opener takes the name literally (no extended-filename
  // syntax), so brackets in a path are not filters.
  if (fits_open_diskfile(&f, path.c_str(), READONLY, &status) != 0)
    throw Error(path + ": cannot open as FITS (" + fits_reason(status) + ")");
  struct Closer {
    fitsfile* f;
    ~Closer() {
      int s = 0;
      fits_close_file(f, &s);
    }
  } closer{f};

  int bitpix = 0, naxis = 0;
  long naxes[3] = {0, 0, 0};
  if (fits_get_img_param(f, 3, &bitpix, &naxis, naxes, &status) != 0)
    throw Error(what + ": cannot read the image header (" + fits_reason(status) + ")");
  if (naxis != 3)
    throw Error(what + ": must be a 3-D cube (NAXIS = 3), found NAXIS = " + std::to_string(naxis));
  for (long n : naxes)
    if (n < 0) throw Error(what + ": negative NAXISi");
  check_grid_size(what, uint64_t(naxes[0]), uint64_t(naxes[1]), uint64_t(naxes[2]));
  for (long n : naxes)
    if (n > std::numeric_limits<int>::max())
      throw Error(what + ": a size exceeds " + std::to_string(std::numeric_limits<int>::max()));

  DensityGrid grid;
  grid.shape.nx = int(naxes[0]);
  grid.shape.ny = int(naxes[1]);
  grid.shape.nz = int(naxes[2]);

  double cdelt[3];
  int found = 0;
  for (int a = 0; a < 3; ++a) {
    const std::string axis = std::to_string(a + 1);
    if (fits_double_key(f, "CDELT" + axis, cdelt[a], what)) ++found;
    std::string unit;
    if (fits_string_key(f, "CUNIT" + axis, unit) && trimmed_lower(unit) != "pc" &&
        !trimmed_lower(unit).empty())
      throw Error(what + ": CUNIT" + axis + " = '" + unit + "'; only parsecs ('pc') are accepted");
  }
  if (found != 0 && found != 3)
    throw Error(what + ": has " + std::to_string(found) + " of CDELT1, CDELT2, CDELT3; give all three or none");
  double voxel = 0;
  if (found == 3) {
    // Signs first: a negative step is a flipped axis, whatever the sizes say.
    static const char* const kAxis[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      const std::string key = "CDELT" + std::to_string(a + 1) + " = " + to_text(cdelt[a]);
      if (cdelt[a] < 0)
        throw Error(what + ": " + key + ": the " + kAxis[a] +
                    " axis is flipped (a negative step), which is not supported; store the data in "
                    "ascending order with a positive CDELT" + std::to_string(a + 1));
      if (!(cdelt[a] > 0)) throw Error(what + ": " + key + ": a voxel size must be positive");
    }
    for (int a = 1; a < 3; ++a)
      if (std::fabs(cdelt[a] - cdelt[0]) > 1e-6 * std::fabs(cdelt[0]))
        throw Error(what + ": voxels must be cubes, but CDELT1 = " + to_text(cdelt[0]) + " and CDELT" +
                    std::to_string(a + 1) + " = " + to_text(cdelt[a]));
    voxel = cdelt[0];
    if (voxel_size_pc > 0 && std::fabs(voxel_size_pc - voxel) > 1e-6 * voxel)
      throw Error(what + ": the scene's voxel size " + to_text(voxel_size_pc) +
                  " pc disagrees with the file's CDELT1 = " + to_text(voxel) + " pc");
  } else {
    if (!(voxel_size_pc > 0) || !std::isfinite(voxel_size_pc))
      throw Error(what + ": no CDELT1/2/3 keywords and no voxel size given (voxel_size_pc)");
    voxel = voxel_size_pc;
  }
  if (!(static_cast<float>(voxel) > 0) || !std::isfinite(static_cast<float>(voxel)))
    throw Error(what + ": voxel size " + to_text(voxel) + " pc is not representable");
  grid.shape.voxel = static_cast<float>(voxel);

  double crpix[3], crval[3];
  int have_pix = 0, have_val = 0;
  for (int a = 0; a < 3; ++a) {
    const std::string axis = std::to_string(a + 1);
    have_pix += fits_double_key(f, "CRPIX" + axis, crpix[a], what) ? 1 : 0;
    have_val += fits_double_key(f, "CRVAL" + axis, crval[a], what) ? 1 : 0;
  }
  if (have_pix + have_val != 0) {
    if (have_pix != 3 || have_val != 3)
      throw Error(what + ": give CRPIXi and CRVALi on all three axes, or none (origin 0)");
    const double v = grid.shape.voxel;
    double origin[3];
    for (int a = 0; a < 3; ++a) {
      origin[a] = crval[a] + (0.5 - crpix[a]) * v;
      if (!(std::fabs(origin[a]) <= 1e30))
        throw Error(what + ": CRVAL" + std::to_string(a + 1) + " = " + to_text(crval[a]) + " and CRPIX" +
                    std::to_string(a + 1) + " = " + to_text(crpix[a]) + " put the grid's corner at " +
                    to_text(origin[a]) + " pc, beyond 1e30 pc (single precision)");
    }
    grid.shape.origin = Vec3{float(origin[0]), float(origin[1]), float(origin[2])};
  }

  try {
    grid.tau_v.resize(grid.shape.count());
  } catch (const std::bad_alloc&) {
    throw Error(what + ": out of memory allocating " +
                bytes_text(double(grid.shape.count()) * sizeof(float)));
  }
  // Undefined pixels (BLANK in integer images) become NaN and are refused below.
  float null_value = std::numeric_limits<float>::quiet_NaN();
  int any_null = 0;
  if (fits_read_img(f, TFLOAT, 1, LONGLONG(grid.shape.count()), &null_value, grid.tau_v.data(),
                    &any_null, &status) != 0)
    throw Error(what + ": cannot read the values (" + fits_reason(status) + ")");
  if (any_null) {
    for (size_t i = 0; i < grid.tau_v.size(); ++i) {
      if (!std::isnan(grid.tau_v[i])) continue;
      const size_t nx = size_t(grid.shape.nx), ny = size_t(grid.shape.ny);
      throw Error(what + ": voxel (x=" + std::to_string(i % nx) + ", y=" +
                  std::to_string(i / nx % ny) + ", z=" + std::to_string(i / (nx * ny)) +
                  ") (index " + std::to_string(i) +
                  ") is undefined (NaN, Inf or BLANK in the file); tau_v must be finite and >= 0");
    }
  }
  check_grid_values(what, grid.shape, grid.tau_v);
  return grid;
}

}  // namespace nebula
