// The HDF5 image file: /image float32 [bands][height][width], row 0 at the
// top, one checksummed chunk per band, with the band names, units, exposure,
// schema version and metadata entries as attributes of the root group
// (docs/image_files.md).
#include <hdf5.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <vector>

#include "core/error.h"
#include "hdf5io/hdf5_support.h"
#include "imageio/image_formats.h"

namespace nebula::imageio_detail {

namespace {

using hdf5io::Handle;
using hdf5io::with_reason;

// ---------------------------------------------------------------- writing

// Fixed-length NUL-terminated strings: they live in the checksummed
// attribute message, not in the unchecked global heap of variable strings.
void write_string(hid_t object, const std::string& name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  if (!type.valid() || !space.valid() || H5Tset_size(type.get(), value.size() + 1) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLTERM) < 0)
    throw Error(with_reason("making the string attribute " + name));
  Handle attr(H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  if (!attr.valid() || H5Awrite(attr.get(), type.get(), value.c_str()) < 0)
    throw Error(with_reason("writing attribute " + name));
}

// The band names as a 1-D array of fixed-length strings (h5py: a list).
void write_string_array(hid_t object, const std::string& name, const std::vector<std::string>& values) {
  size_t longest = 1;
  for (const std::string& v : values) longest = std::max(longest, v.size() + 1);
  std::vector<char> buffer(values.size() * longest, '\0');
  for (size_t i = 0; i < values.size(); ++i) std::copy(values[i].begin(), values[i].end(), &buffer[i * longest]);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  const hsize_t n = values.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  if (!type.valid() || !space.valid() || H5Tset_size(type.get(), longest) < 0 ||
      H5Tset_strpad(type.get(), H5T_STR_NULLTERM) < 0)
    throw Error(with_reason("making the string array attribute " + name));
  Handle attr(H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid() || H5Awrite(attr.get(), type.get(), buffer.data()) < 0)
    throw Error(with_reason("writing attribute " + name));
}

void write_scalar(hid_t object, const char* name, hid_t file_type, hid_t memory_type,
                  const void* value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!space.valid() || !attr.valid() || H5Awrite(attr.get(), memory_type, value) < 0)
    throw Error(with_reason(std::string("writing attribute ") + name));
}

// ---------------------------------------------------------------- reading

const char* class_name(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER: return "integer";
    case H5T_FLOAT: return "float";
    case H5T_STRING: return "string";
    case H5T_COMPOUND: return "compound";
    case H5T_ENUM: return "enum";
    case H5T_VLEN: return "variable-length";
    case H5T_ARRAY: return "array";
    default: return "other";
  }
}

// Reads one open file; every failure names the file and the field.
class Reader {
 public:
  Reader(const std::string& path, hid_t file) : path_(path), file_(file) {}

  // Opens a scalar attribute of the root group of class WANT.
  Handle open_attribute(const std::string& name, const std::string& expected, H5T_class_t want) const {
    const htri_t exists = H5Aexists(file_, name.c_str());
    if (exists < 0) fail(path_, name, expected, with_reason("an unreadable root group (damaged file?)"));
    if (exists == 0) fail(path_, name, expected + " on /", "no such attribute (not a nebula image?)");
    Handle attr(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
    if (!attr.valid()) fail(path_, name, expected, with_reason("an attribute that cannot be opened"));
    Handle type(H5Aget_type(attr.get()), H5Tclose);
    const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
    if (cls != want) fail(path_, name, expected, std::string("an attribute of class ") + class_name(cls));
    Handle space(H5Aget_space(attr.get()), H5Sclose);
    const hssize_t points = space.valid() ? H5Sget_simple_extent_npoints(space.get()) : -1;
    if (points != 1) fail(path_, name, expected, std::to_string(points) + " elements");
    return attr;
  }

  std::string string_attribute(const std::string& name) const {
    const std::string expected = "a scalar string attribute";
    const Handle attr = open_attribute(name, expected, H5T_STRING);
    Handle file_type(H5Aget_type(attr.get()), H5Tclose);
    Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (!file_type.valid() || !memory_type.valid())
      fail(path_, name, expected, with_reason("an unreadable type"));
    H5Tset_cset(memory_type.get(), H5Tget_cset(file_type.get()));
    if (H5Tis_variable_str(file_type.get()) > 0) {
      H5Tset_size(memory_type.get(), H5T_VARIABLE);
      char* text = nullptr;
      if (H5Aread(attr.get(), memory_type.get(), &text) < 0) fail(path_, name, expected, with_reason("a read error"));
      std::string value = text != nullptr ? text : "";
      H5free_memory(text);
      return value;
    }
    const size_t size = H5Tget_size(file_type.get());
    if (size == 0 || size > (1u << 20))
      fail(path_, name, expected, "a fixed-length string of " + std::to_string(size) + " bytes");
    H5Tset_size(memory_type.get(), size);
    H5Tset_strpad(memory_type.get(), H5T_STR_NULLPAD);
    std::vector<char> buffer(size + 1, '\0');
    if (H5Aread(attr.get(), memory_type.get(), buffer.data()) < 0)
      fail(path_, name, expected, with_reason("a read error"));
    std::string value(buffer.data());  // up to the first NUL
    if (H5Tget_strpad(file_type.get()) == H5T_STR_SPACEPAD)
      while (!value.empty() && value.back() == ' ') value.pop_back();
    return value;
  }

  // Band names: a 1-D array of fixed-length strings (schema 2).
  std::vector<std::string> string_array(const std::string& name, size_t count) const {
    const std::string expected = std::to_string(count) + " band names (the first dimension of /image)";
    const htri_t exists = H5Aexists(file_, name.c_str());
    if (exists <= 0) fail(path_, name, expected, "no such attribute (not a nebula image?)");
    Handle attr(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
    Handle type(attr.valid() ? H5Aget_type(attr.get()) : -1, H5Tclose);
    Handle space(attr.valid() ? H5Aget_space(attr.get()) : -1, H5Sclose);
    if (!type.valid() || !space.valid() || H5Tget_class(type.get()) != H5T_STRING ||
        H5Tis_variable_str(type.get()) != 0)
      fail(path_, name, expected, "not an array of fixed-length strings");
    const hssize_t points = H5Sget_simple_extent_npoints(space.get());
    if (points < 0 || size_t(points) != count) fail(path_, name, expected, std::to_string(points) + " strings");
    const size_t size = H5Tget_size(type.get());
    if (size == 0 || size > 4096) fail(path_, name, expected, "strings of " + std::to_string(size) + " bytes");
    std::vector<char> buffer(size * count + 1, '\0');
    Handle memory_type(H5Tcopy(type.get()), H5Tclose);
    if (!memory_type.valid() || H5Aread(attr.get(), memory_type.get(), buffer.data()) < 0)
      fail(path_, name, expected, with_reason("a read error"));
    std::vector<std::string> out;
    for (size_t i = 0; i < count; ++i) out.emplace_back(&buffer[i * size], strnlen(&buffer[i * size], size));
    return out;
  }

  // A metadata entry: an integer, float or string attribute.
  MetaValue entry(const std::string& name) const {
    Handle attr(H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose);
    Handle type(attr.valid() ? H5Aget_type(attr.get()) : -1, H5Tclose);
    const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
    if (cls == H5T_INTEGER) return MetaValue(integer_attribute(name));
    if (cls == H5T_FLOAT) return MetaValue(double_attribute(name));
    if (cls == H5T_STRING) return MetaValue(string_attribute(name));
    fail(path_, name, "an integer, float or string attribute (a metadata entry)",
         std::string("an attribute of class ") + class_name(cls));
  }

  double double_attribute(const std::string& name) const {
    const std::string expected = "a scalar float attribute";
    const Handle attr = open_attribute(name, expected, H5T_FLOAT);
    double value = 0;
    if (H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &value) < 0) fail(path_, name, expected, with_reason("a read error"));
    return value;
  }

  long long integer_attribute(const std::string& name) const {
    const std::string expected = "a scalar integer attribute";
    const Handle attr = open_attribute(name, expected, H5T_INTEGER);
    long long value = 0;
    if (H5Aread(attr.get(), H5T_NATIVE_LLONG, &value) < 0) fail(path_, name, expected, with_reason("a read error"));
    return value;
  }

 private:
  const std::string& path_;
  hid_t file_;
};

// The root group's attribute names in the order they were written (files
// without a creation-order index: by name).
std::vector<std::string> attribute_names(const std::string& path, hid_t file) {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5A_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->push_back(name);
    return 0;
  };
  if (H5Aiterate2(file, H5_INDEX_CRT_ORDER, H5_ITER_INC, nullptr, collect, &names) >= 0) return names;
  names.clear();
  if (H5Aiterate2(file, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect, &names) >= 0) return names;
  fail(path, "/", "a readable list of attributes", with_reason("an unreadable root group (damaged file?)"));
}

}  // namespace

void write_hdf5(const Image& image, const ImageMetadata& metadata, const std::string& file_name) {
  write_hdf5_cube({&image}, {}, metadata, file_name);
}

void write_hdf5_cube(const std::vector<const Image*>& images, const std::vector<CubeAxis>& cube_axes,
                     const ImageMetadata& metadata, const std::string& file_name) {
  const std::lock_guard<std::mutex> lock(hdf5io::hdf5_mutex());
  hdf5io::silence_hdf5_errors();
  const Image& image = *images.front();

  // The core driver builds the file in memory and writes it out on close:
  // HDF5 1.10 recovers from a failed write there (tables/table_file.cpp has
  // the story). The 1.10 format (read by HDF5 >= 1.10) checksums all the
  // metadata, the chunk index included; the 1.8 format's chunk index has
  // no checksum, and a damaged one there passed pixels off as unfiltered.
  // Tracking creation order keeps the metadata entries in the order given.
  const size_t bytes = image.pixels.size() * sizeof(float) * images.size();
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  Handle creation(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  if (!access.valid() || !creation.valid() ||
      H5Pset_fapl_core(access.get(), bytes + (size_t(1) << 20), 1) < 0 ||
      H5Pset_libver_bounds(access.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST) < 0 ||
      H5Pset_attr_creation_order(creation.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED) < 0)
    throw Error(with_reason("setting up HDF5 file access"));
  Handle file(H5Fcreate(file_name.c_str(), H5F_ACC_TRUNC, creation.get(), access.get()), H5Fclose);
  if (!file.valid()) throw Error(with_reason("creating the HDF5 file"));
  const hid_t f = file.get();

  // [axis 1, ..., axis K,] bands, rows, columns.
  std::vector<hsize_t> dims;
  for (const CubeAxis& a : cube_axes) dims.push_back(a.values.size());
  dims.insert(dims.end(), {hsize_t(image.bands.size()), hsize_t(image.height), hsize_t(image.width)});
  const int rank = static_cast<int>(dims.size());
  Handle space(H5Screate_simple(rank, dims.data(), nullptr), H5Sclose);
  if (!space.valid()) throw Error(with_reason("creating the dataspace of /image"));
  // One chunk per band, each with a Fletcher-32 checksum: damaged pixels
  // are refused on reading, as damaged metadata are.
  std::vector<hsize_t> chunk(dims.size(), 1);
  chunk[rank - 2] = dims[rank - 2];
  chunk[rank - 1] = dims[rank - 1];
  Handle layout(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (!layout.valid() || H5Pset_chunk(layout.get(), rank, chunk.data()) < 0 || H5Pset_fletcher32(layout.get()) < 0)
    throw Error(with_reason("setting up the layout of /image"));
  Handle set(H5Dcreate2(f, "/image", H5T_IEEE_F32LE, space.get(), H5P_DEFAULT, layout.get(), H5P_DEFAULT),
             H5Dclose);
  if (!set.valid()) throw Error(with_reason("creating /image"));
  std::vector<float> all;
  const std::vector<float>* pixels = &image.pixels;
  if (images.size() > 1) {
    all.reserve(image.pixels.size() * images.size());
    for (const Image* each : images) all.insert(all.end(), each->pixels.begin(), each->pixels.end());
    pixels = &all;
  }
  if (H5Dwrite(set.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, pixels->data()) < 0)
    throw Error(with_reason("writing /image"));
  if (!set.close()) throw Error(with_reason("closing /image"));
  // The cube's axes: /axes/<key> holds each one's values, the root
  // attribute "axes" their keys in the order of /image's leading dimensions.
  if (!cube_axes.empty()) {
    Handle group(H5Gcreate2(f, "/axes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!group.valid()) throw Error(with_reason("creating /axes"));
    std::vector<std::string> keys;
    for (const CubeAxis& a : cube_axes) {
      keys.push_back(a.key);
      const hsize_t n = a.values.size();
      Handle line(H5Screate_simple(1, &n, nullptr), H5Sclose);
      Handle values(H5Dcreate2(group.get(), a.key.c_str(), H5T_IEEE_F64LE, line.get(), H5P_DEFAULT, H5P_DEFAULT,
                               H5P_DEFAULT),
                    H5Dclose);
      if (!line.valid() || !values.valid() ||
          H5Dwrite(values.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.values.data()) < 0 ||
          !values.close())
        throw Error(with_reason("writing /axes/" + a.key));
    }
    write_string_array(f, "axes", keys);
  }

  const int schema = kSchemaVersion;
  write_scalar(f, kSchemaName, H5T_STD_I32LE, H5T_NATIVE_INT, &schema);
  write_string_array(f, kBandsName, image.bands);
  write_string(f, kUnitsName, metadata.units);
  write_scalar(f, kExposureName, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &metadata.exposure);
  for (const auto& [key, value] : metadata.entries) {
    if (value.kind == MetaValue::Kind::Integer)
      write_scalar(f, key.c_str(), H5T_STD_I64LE, H5T_NATIVE_LLONG, &value.integer);
    else if (value.kind == MetaValue::Kind::Real)
      write_scalar(f, key.c_str(), H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value.real);
    else
      write_string(f, key, value.text);
  }
  if (!metadata.scene_text.empty()) write_string(f, kSceneName, metadata.scene_text);

  if (!file.close()) throw Error(with_reason("writing the HDF5 file"));
}

Image read_hdf5(const std::string& path, ImageMetadata* metadata) {
  const std::lock_guard<std::mutex> lock(hdf5io::hdf5_mutex());
  hdf5io::silence_hdf5_errors();

  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw Error(path + ": not an HDF5 file (no HDF5 signature); expected a nebula image");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) throw Error(with_reason(path + ": cannot open as HDF5 (truncated or corrupt?)"));
  const hid_t f = file.get();
  const Reader r(path, f);

  // The schema first: a newer layout would otherwise fail confusingly.
  const long long schema = r.integer_attribute(kSchemaName);
  if (schema != 1 && schema != kSchemaVersion)
    fail(path, kSchemaName, "1 or 2 (the image schemas this reader knows)", std::to_string(schema));

  const std::string expected = "a 3-D float dataset [bands][height][width]";
  const htri_t exists = H5Lexists(f, "/image", H5P_DEFAULT);
  if (exists < 0) fail(path, "/image", expected, with_reason("an unreadable root group (damaged file?)"));
  if (exists == 0) fail(path, "/image", expected, "no such dataset");
  Handle set(H5Dopen2(f, "/image", H5P_DEFAULT), H5Dclose);
  if (!set.valid()) fail(path, "/image", expected, with_reason("an object that cannot be opened as a dataset"));
  Handle type(H5Dget_type(set.get()), H5Tclose);
  const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
  if (cls != H5T_FLOAT) fail(path, "/image", expected, std::string("a dataset of class ") + class_name(cls));
  Handle space(H5Dget_space(set.get()), H5Sclose);
  const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
  if (rank != 3) fail(path, "/image", expected, "rank " + std::to_string(rank));
  hsize_t dims[3] = {0, 0, 0};
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  const std::string shape =
      "[" + std::to_string(dims[0]) + "][" + std::to_string(dims[1]) + "][" + std::to_string(dims[2]) + "]";
  if (dims[0] == 0 || dims[1] == 0 || dims[2] == 0 || dims[1] > INT_MAX || dims[2] > INT_MAX ||
      dims[0] > kMaxElements / dims[1] / dims[2])
    fail(path, "/image", expected + " of 1 to 2^29 values", shape);
  // The data must fit in the file: a truncated file is refused before a
  // large allocation. (Our files are chunked, with no single offset; a
  // contiguous dataset from elsewhere must also end inside the file.)
  const hsize_t stored = H5Dget_storage_size(set.get());
  const haddr_t offset = H5Dget_offset(set.get());
  std::error_code ec;
  const auto file_size = std::filesystem::file_size(path, ec);
  if (!ec && (stored > file_size || (offset != HADDR_UNDEF && offset + stored > file_size)))
    fail(path, "/image", expected + " inside the file", "data past its end (truncated file?)");

  Image image;
  image.width = static_cast<int>(dims[2]);
  image.height = static_cast<int>(dims[1]);
  image.pixels.resize(dims[0] * dims[1] * dims[2]);
  if (H5Dread(set.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, image.pixels.data()) < 0)
    fail(path, "/image", "a readable dataset", with_reason("an HDF5 read error"));

  Handle bands_attr(H5Aexists(f, kBandsName) > 0 ? H5Aopen(f, kBandsName, H5P_DEFAULT) : -1, H5Aclose);
  Handle bands_space(bands_attr.valid() ? H5Aget_space(bands_attr.get()) : -1, H5Sclose);
  const bool scalar_bands = bands_space.valid() && H5Sget_simple_extent_type(bands_space.get()) == H5S_SCALAR;
  if (schema == 1 || scalar_bands) {  // the band names comma-separated in one string (schema 1)
    const std::string bands = r.string_attribute(kBandsName);
    image.bands = split_bands(bands);
    if (image.bands.size() != dims[0])
      fail(path, kBandsName, std::to_string(dims[0]) + " comma-separated band names (the first dimension of /image)",
           "'" + bands + "'");
  } else {
    image.bands = r.string_array(kBandsName, dims[0]);
  }

  ImageMetadata m;
  m.units = r.string_attribute(kUnitsName);
  m.exposure = r.double_attribute(kExposureName);
  if (!std::isfinite(m.exposure) || m.exposure <= 0)
    fail(path, kExposureName, "a finite positive number", exact_text(m.exposure));
  for (const std::string& name : attribute_names(path, f)) {
    if (name == kSchemaName || name == kBandsName || name == kUnitsName || name == kExposureName) continue;
    if (name == kSceneName) {
      m.scene_text = r.string_attribute(name);
      continue;
    }
    m.entries.emplace_back(name, schema == 1 ? MetaValue(r.string_attribute(name)) : r.entry(name));
  }
  *metadata = m;
  return image;
}

}  // namespace nebula::imageio_detail
