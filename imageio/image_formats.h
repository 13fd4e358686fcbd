#pragma once
// Internal to imageio/: the writers and readers behind image_output.h, one
// file per library, and the small pieces they share.
#include <cstddef>
#include <string>
#include <vector>

#include "core/image.h"
#include "imageio/image_output.h"

namespace nebula::imageio_detail {

// Writers get an image and metadata that passed every check of write_image
// and the name of an empty temporary file to fill. They throw Error with the
// reason only; write_image adds "cannot write PATH: ".
void write_hdf5(const Image& image, const ImageMetadata& metadata, const std::string& file);
void write_fits(const Image& image, const ImageMetadata& metadata, const std::string& file);
void write_exr(const Image& image, const ImageMetadata& metadata, const std::string& file);
void write_png(const Image& image, const ImageMetadata& metadata, const std::string& file);
// Cubes (write_cube): the images one after another, first axis slowest.
void write_hdf5_cube(const std::vector<const Image*>& images, const std::vector<CubeAxis>& axes,
                     const ImageMetadata& metadata, const std::string& file);
void write_fits_cube(const std::vector<const Image*>& images, const std::vector<CubeAxis>& axes,
                     const ImageMetadata& metadata, const std::string& file);

// Readers get an existing regular file and throw Error starting "PATH: ".
// read_image then checks the band names and that every pixel is finite.
Image read_hdf5(const std::string& path, ImageMetadata* metadata);
Image read_fits(const std::string& path, ImageMetadata* metadata);
Image read_exr(const std::string& path, ImageMetadata* metadata);
std::vector<Image> read_fits_cube_file(const std::string& path, std::vector<CubeAxis>* axes);

// The most floats a reader allocates (2 GiB): a malformed header claiming
// more is refused instead of exhausting memory.
constexpr size_t kMaxElements = size_t(1) << 29;

// Names the HDF5 layout uses on its root group; metadata keys may not take
// them (nor the FITS layout's keywords: see image_output.cpp).
inline const char* const kBandsName = "bands";
inline const char* const kUnitsName = "units";
inline const char* const kExposureName = "exposure";
inline const char* const kSchemaName = "schema_version";
inline const char* const kSceneName = "scene_toml";
// 2: typed entries (numbers as numbers), HDF5 band names as a string array,
// EXR channels R, G, B for the bands R, V, B. Readers take 1 and 2.
constexpr int kSchemaVersion = 2;

// "PATH: FIELD: expected EXPECTED, found FOUND", the form of every read error.
[[noreturn]] void fail(const std::string& path, const std::string& field,
                       const std::string& expected, const std::string& found);

// Band lists travel as one comma-separated string ("B,V,R"); band names
// contain no commas.
std::string join_bands(const std::vector<std::string>& bands);
std::vector<std::string> split_bands(const std::string& text);

// TEXT with line breaks turned into spaces (library messages in one-line errors).
std::string one_line_text(std::string text);

// Shortest text that reads back as the same double.
std::string exact_text(double value);
// Parses all of TEXT as a double; false if anything is left over.
bool parse_double(const std::string& text, double& value);

}  // namespace nebula::imageio_detail
