#include "tables/table_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <mutex>
#include <new>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "hdf5io/hdf5_support.h"

namespace nebula {

namespace {

namespace fs = std::filesystem;

using hdf5io::Handle;
using hdf5io::with_reason;

// Largest dataset we agree to allocate for; a malformed file claiming more is
// refused instead of exhausting memory.
constexpr hsize_t kMaxElements = hsize_t(1) << 28;

const char* class_name(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER: return "integer";
    case H5T_FLOAT: return "float";
    case H5T_STRING: return "string";
    case H5T_BITFIELD: return "bitfield";
    case H5T_OPAQUE: return "opaque";
    case H5T_COMPOUND: return "compound";
    case H5T_REFERENCE: return "reference";
    case H5T_ENUM: return "enum";
    case H5T_VLEN: return "variable-length";
    case H5T_ARRAY: return "array";
    default: return "unknown-class";
  }
}

// ---------------------------------------------------------------- writing

void write_dataset(hid_t file, const char* name, hid_t file_type, hid_t memory_type,
                   const void* data, std::initializer_list<hsize_t> dims) {
  const std::vector<hsize_t> extent(dims);
  Handle space(H5Screate_simple(static_cast<int>(extent.size()), extent.data(), nullptr),
               H5Sclose);
  if (!space.valid()) throw Error(with_reason(std::string("creating the dataspace of ") + name));
  Handle set(H5Dcreate2(file, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid()) throw Error(with_reason(std::string("creating ") + name));
  if (H5Dwrite(set.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw Error(with_reason(std::string("writing ") + name));
  if (!set.close()) throw Error(with_reason(std::string("closing ") + name));
}

void write_attribute(hid_t file, const char* name, hid_t file_type, hid_t memory_type,
                     const void* value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(file, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  if (!space.valid() || !attr.valid())
    throw Error(with_reason(std::string("creating attribute ") + name));
  if (H5Awrite(attr.get(), memory_type, value) < 0)
    throw Error(with_reason(std::string("writing attribute ") + name));
}

// Strings are fixed-length and NUL-terminated: they live inside the
// (checksummed) attribute message rather than in the unchecked global heap
// that variable-length strings use.
void write_string_attribute(hid_t file, const char* name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), value.size() + 1) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLTERM) < 0 ||
      H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0)
    throw Error(with_reason(std::string("making the string type of ") + name));
  write_attribute(file, name, type.get(), type.get(), value.c_str());
}

// Writes the table with HDF5's core driver: the file is built in memory and
// written out through its backing store. In our tests HDF5 1.10 recovered
// from a failed write there (file-size limit), whereas a failed flush of a
// plain (sec2) file left the library crashing at exit. The 1.8 format (read by HDF5 >= 1.8) checksums the
// metadata, so a reader refuses damaged metadata instead of parsing it.
void write_hdf5(const ScatteringTable& t, const std::string& file_name) {
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid() || H5Pset_fapl_core(access.get(), size_t(1) << 20, 1) < 0 ||
      H5Pset_libver_bounds(access.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST) < 0)
    throw Error(with_reason("setting up HDF5 file access"));
  Handle file(H5Fcreate(file_name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get()), H5Fclose);
  if (!file.valid()) throw Error(with_reason("creating the HDF5 file"));
  const hid_t f = file.get();
  const hsize_t nt = t.tau.size(), nm = t.mu.size();

  write_dataset(f, "/P", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, t.P.data(), {nt, nm});
  write_dataset(f, "/P_stderr", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, t.P_stderr.data(), {nt, nm});
  write_dataset(f, "/tau", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, t.tau.data(), {nt});
  write_dataset(f, "/mu_edges", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, t.mu_edges.data(), {nm + 1});
  write_dataset(f, "/mu", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, t.mu.data(), {nm});
  write_dataset(f, "/total", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, t.total.data(), {nt});
  write_dataset(f, "/total_stderr", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, t.total_stderr.data(), {nt});
  write_dataset(f, "/unscattered", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, t.unscattered.data(), {nt});

  auto f64 = [&](const char* name, double v) {
    write_attribute(f, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v);
  };
  auto u64 = [&](const char* name, uint64_t v) {
    write_attribute(f, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &v);
  };
  auto i32 = [&](const char* name, int32_t v) {
    write_attribute(f, name, H5T_STD_I32LE, H5T_NATIVE_INT32, &v);
  };
  f64("albedo", t.albedo);
  f64("g", t.g);
  write_string_attribute(f, "phase", t.phase);
  write_string_attribute(f, "geometry", t.geometry);
  write_string_attribute(f, "illumination", t.illumination);
  write_string_attribute(f, "mu_binning", to_string(t.mu_binning));
  write_string_attribute(f, "rng", t.rng);
  write_string_attribute(f, "generator", t.generator);
  u64("photons_per_row", t.photons_per_row);
  u64("thin_boost", t.thin_boost);
  u64("seed", t.seed);
  u64("capped_photons", t.capped_photons);
  u64("scattering_events", t.scattering_events);
  i32("schema_version", t.schema_version);
  i32("max_orders", t.max_orders);
  i32("forced_first_scattering", t.forced_first_scattering ? 1 : 0);
  f64("roulette_threshold", t.roulette_threshold);
  f64("roulette_survival", t.roulette_survival);

  if (!file.close()) throw Error(with_reason("writing the HDF5 file"));
}

// ---------------------------------------------------------------- reading

// Reads one file; every failure names the file and the field.
class Reader {
 public:
  Reader(const std::string& path, hid_t file) : path_(path), file_(file) {}

  [[noreturn]] void fail(const std::string& field, const std::string& expected,
                         const std::string& found) const {
    throw Error(path_ + ": " + field + ": expected " + expected + ", found " + found);
  }

  // A float dataset of the given shape; a dimension of -1 takes any length.
  template <class T>
  std::vector<T> dataset(const char* name, std::initializer_list<long long> shape,
                         const std::string& expected) const {
    const std::string missing = "no such dataset (not a nebula scattering table?)";
    const htri_t exists = H5Lexists(file_, name, H5P_DEFAULT);
    if (exists < 0) fail(name, expected, with_reason("an unreadable root group (damaged file?)"));
    if (exists == 0) fail(name, expected, missing);
    Handle set(H5Dopen2(file_, name, H5P_DEFAULT), H5Dclose);
    if (!set.valid())
      fail(name, expected, with_reason("an object that cannot be opened as a dataset"));
    Handle type(H5Dget_type(set.get()), H5Tclose);
    const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
    if (cls != H5T_FLOAT) fail(name, expected, std::string("a dataset of class ") + class_name(cls));

    Handle space(H5Dget_space(set.get()), H5Sclose);
    if (!space.valid()) fail(name, expected, with_reason("an unreadable dataspace"));
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0) fail(name, expected, with_reason("an unreadable dataspace"));
    if (rank == 0) fail(name, expected, "a scalar or empty dataspace");
    std::vector<hsize_t> dims(rank);
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    std::string found_shape = "rank " + std::to_string(rank) + " ";
    for (hsize_t d : dims) found_shape += "[" + std::to_string(d) + "]";
    if (rank != static_cast<int>(shape.size())) fail(name, expected, found_shape);

    hsize_t count = 1;
    size_t axis = 0;
    for (long long want : shape) {
      const hsize_t have = dims[axis++];
      if (want >= 0 && have != static_cast<hsize_t>(want)) fail(name, expected, found_shape);
      if (have > kMaxElements || count * have > kMaxElements)
        fail(name, expected, found_shape + ", more than 2^28 elements");
      count *= have;
    }

    std::vector<T> data(count);
    const hid_t memory_type = sizeof(T) == sizeof(float) ? H5T_NATIVE_FLOAT : H5T_NATIVE_DOUBLE;
    if (count > 0 &&
        H5Dread(set.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
      fail(name, "a readable dataset", with_reason("an HDF5 read error"));
    return data;
  }

  double attribute_f64(const char* name) const {
    const std::string expected = "a scalar float64 attribute";
    Handle attr = open_attribute(name, expected, H5T_FLOAT);
    double v = 0.0;
    if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &v) < 0) fail(name, expected, with_reason("a read error"));
    return v;
  }

  bool has_attribute(const char* name) const { return H5Aexists(file_, name) > 0; }

  uint64_t attribute_u64(const char* name) const {
    const std::string expected = "a scalar non-negative integer (uint64) attribute";
    Handle attr = open_attribute(name, expected, H5T_INTEGER);
    if (is_signed(attr)) {
      const long long v = read_int64(attr, name, expected);
      if (v < 0) fail(name, expected, std::to_string(v));
      return static_cast<uint64_t>(v);
    }
    unsigned long long v = 0;
    if (H5Aread(attr.get(), H5T_NATIVE_ULLONG, &v) < 0) fail(name, expected, with_reason("a read error"));
    return v;
  }

  int attribute_i32(const char* name) const {
    const std::string expected = "a scalar int32 attribute";
    Handle attr = open_attribute(name, expected, H5T_INTEGER);
    long long v = 0;
    if (is_signed(attr)) {
      v = read_int64(attr, name, expected);
    } else {
      unsigned long long u = 0;
      if (H5Aread(attr.get(), H5T_NATIVE_ULLONG, &u) < 0) fail(name, expected, with_reason("a read error"));
      if (u > 0x7fffffffull) fail(name, expected, std::to_string(u) + " (out of int32 range)");
      v = static_cast<long long>(u);
    }
    if (v < INT32_MIN || v > INT32_MAX) fail(name, expected, std::to_string(v) + " (out of int32 range)");
    return static_cast<int>(v);
  }

  // Fixed-length or variable-length, either padding.
  std::string attribute_string(const char* name) const {
    const std::string expected = "a scalar string attribute";
    Handle attr = open_attribute(name, expected, H5T_STRING);
    Handle file_type(H5Aget_type(attr.get()), H5Tclose);
    Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (!file_type.valid() || !memory_type.valid()) fail(name, expected, with_reason("an unreadable type"));
    H5Tset_cset(memory_type.get(), H5Tget_cset(file_type.get()));

    if (H5Tis_variable_str(file_type.get()) > 0) {
      H5Tset_size(memory_type.get(), H5T_VARIABLE);
      char* text = nullptr;
      if (H5Aread(attr.get(), memory_type.get(), &text) < 0) fail(name, expected, with_reason("a read error"));
      std::string value = text != nullptr ? text : "";
      H5free_memory(text);
      return value;
    }
    const size_t size = H5Tget_size(file_type.get());
    if (size == 0 || size > (1u << 20)) fail(name, expected, "a fixed-length string of " + std::to_string(size) + " bytes");
    H5Tset_size(memory_type.get(), size);
    H5Tset_strpad(memory_type.get(), H5T_STR_NULLPAD);
    std::vector<char> buffer(size + 1, '\0');
    if (H5Aread(attr.get(), memory_type.get(), buffer.data()) < 0) fail(name, expected, with_reason("a read error"));
    std::string value(buffer.data());  // up to the first NUL
    while (!value.empty() && value.back() == ' ') value.pop_back();  // space padding
    return value;
  }

 private:
  Handle open_attribute(const char* name, const std::string& expected, H5T_class_t want) const {
    const htri_t exists = H5Aexists(file_, name);
    if (exists < 0) fail(name, expected, with_reason("an unreadable root group (damaged file?)"));
    if (exists == 0)
      fail(name, expected + " on /", "no such attribute (not a nebula scattering table?)");
    Handle attr(H5Aopen(file_, name, H5P_DEFAULT), H5Aclose);
    if (!attr.valid()) fail(name, expected, with_reason("an attribute that cannot be opened"));
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
    if (cls != want) fail(name, expected, std::string("an attribute of class ") + class_name(cls));
    Handle space(H5Aget_space(attr.get()), H5Sclose);
    const hssize_t points = space.valid() ? H5Sget_simple_extent_npoints(space.get()) : -1;
    if (points != 1) fail(name, expected, std::to_string(points) + " elements");
    return attr;
  }

  bool is_signed(const Handle& attr) const {
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    return H5Tget_sign(type.get()) == H5T_SGN_2;
  }

  long long read_int64(const Handle& attr, const char* name, const std::string& expected) const {
    long long v = 0;
    if (H5Aread(attr.get(), H5T_NATIVE_LLONG, &v) < 0) fail(name, expected, with_reason("a read error"));
    return v;
  }

  const std::string& path_;
  hid_t file_;
};

ScatteringTable read_hdf5(const std::string& path, hid_t file) {
  const Reader r(path, file);
  ScatteringTable t;

  // The schema first: a newer layout would otherwise fail with confusing errors.
  t.schema_version = r.attribute_i32("schema_version");
  if (t.schema_version != 1)
    r.fail("schema_version", "1 (the only schema this reader knows)", std::to_string(t.schema_version));

  t.tau = r.dataset<double>("/tau", {-1}, "1-D float dataset (the tau_sct axis)");
  t.mu = r.dataset<double>("/mu", {-1}, "1-D float dataset (the mu bin centres)");
  const long long nt = static_cast<long long>(t.tau.size());
  const long long nm = static_cast<long long>(t.mu.size());
  const std::string n_tau = "[" + std::to_string(nt) + "]";
  const std::string grid = "[" + std::to_string(nt) + "][" + std::to_string(nm) + "]";
  t.mu_edges = r.dataset<double>("/mu_edges", {nm + 1},
                                 "1-D float dataset [" + std::to_string(nm + 1) + "] (n_mu + 1, from /mu)");
  t.P = r.dataset<float>("/P", {nt, nm}, "2-D float dataset " + grid + " matching /tau and /mu");
  t.P_stderr = r.dataset<float>("/P_stderr", {nt, nm},
                                "2-D float dataset " + grid + " matching /tau and /mu");
  t.total = r.dataset<double>("/total", {nt}, "1-D float dataset " + n_tau + " matching /tau");
  t.total_stderr = r.dataset<double>("/total_stderr", {nt}, "1-D float dataset " + n_tau + " matching /tau");
  t.unscattered = r.dataset<double>("/unscattered", {nt}, "1-D float dataset " + n_tau + " matching /tau");

  t.albedo = r.attribute_f64("albedo");
  t.g = r.attribute_f64("g");
  t.phase = r.attribute_string("phase");
  t.geometry = r.attribute_string("geometry");
  t.illumination = r.attribute_string("illumination");
  const std::string binning = r.attribute_string("mu_binning");
  if (!parse_angular_binning(binning, t.mu_binning) || binning != to_string(t.mu_binning))
    r.fail("mu_binning", "\"uniform-mu\" or \"uniform-theta\"", "\"" + binning + "\"");
  t.rng = r.attribute_string("rng");
  t.generator = r.attribute_string("generator");
  t.photons_per_row = r.attribute_u64("photons_per_row");
  // Files from before thin rows got more photons have no such attribute: 1.
  t.thin_boost = r.has_attribute("thin_boost") ? r.attribute_u64("thin_boost") : 1;
  t.seed = r.attribute_u64("seed");
  t.capped_photons = r.attribute_u64("capped_photons");
  t.scattering_events = r.attribute_u64("scattering_events");
  t.max_orders = r.attribute_i32("max_orders");
  const int forced = r.attribute_i32("forced_first_scattering");
  if (forced != 0 && forced != 1)
    r.fail("forced_first_scattering", "0 or 1", std::to_string(forced));
  t.forced_first_scattering = forced == 1;
  t.roulette_threshold = r.attribute_f64("roulette_threshold");
  t.roulette_survival = r.attribute_f64("roulette_survival");
  return t;
}

}  // namespace

void write_table(const ScatteringTable& table, const std::string& path, bool overwrite) {
  table.check_consistency(path);
  const std::lock_guard<std::mutex> lock(hdf5io::hdf5_mutex());
  hdf5io::silence_hdf5_errors();

  check_output_target(path, overwrite, "directory", false);

  TemporaryFile temporary(path);
  try {
    write_hdf5(table, temporary.path());
  } catch (const Error& e) {
    throw Error("cannot write " + path + ": " + e.what());
  }
  temporary.publish();
}

namespace {

ScatteringTable read_table_here(const std::string& path) {
  ScatteringTable table;
  {
    const std::lock_guard<std::mutex> lock(hdf5io::hdf5_mutex());
    hdf5io::silence_hdf5_errors();

    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (!fs::exists(status)) throw Error(path + ": cannot read: no such file");
    if (fs::is_directory(status)) throw Error(path + ": cannot read: it is a directory");
    if (std::FILE* probe = std::fopen(path.c_str(), "rb")) {
      std::fclose(probe);
    } else {
      throw Error(path + ": cannot read: " + std::strerror(errno));
    }
    if (H5Fis_hdf5(path.c_str()) <= 0)
      throw Error(path + ": not an HDF5 file (no HDF5 signature); expected a nebula scattering table");

    try {
      Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
      if (!file.valid()) throw Error(with_reason(path + ": cannot open as HDF5 (truncated or corrupt?)"));
      table = read_hdf5(path, file.get());
    } catch (const std::bad_alloc&) {
      throw Error(path + ": out of memory while reading the table");
    }
  }
  table.check_consistency(path);
  return table;
}

}  // namespace

ScatteringTable read_table(const std::string& path) {
  hdf5io::read_in_child_first(path, [&] { read_table_here(path); });
  return read_table_here(path);
}

ScatteringTable read_own_table(const std::string& path) { return read_table_here(path); }

}  // namespace nebula
