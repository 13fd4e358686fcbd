#include "imageio/image_output.h"

#include "hdf5io/hdf5_support.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <regex>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "imageio/image_formats.h"

namespace nebula {

namespace imageio_detail {

void fail(const std::string& path, const std::string& field, const std::string& expected,
          const std::string& found) {
  throw Error(path + ": " + field + ": expected " + expected + ", found " + found);
}

std::string join_bands(const std::vector<std::string>& bands) {
  std::string text;
  for (const std::string& band : bands) text += (text.empty() ? "" : ",") + band;
  return text;
}

std::vector<std::string> split_bands(const std::string& text) {
  std::vector<std::string> bands;
  size_t begin = 0;
  while (true) {
    const size_t comma = text.find(',', begin);
    bands.push_back(text.substr(begin, comma - begin));
    if (comma == std::string::npos) return bands;
    begin = comma + 1;
  }
}

std::string exact_text(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

bool parse_double(const std::string& text, double& value) {
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size() && !text.empty();
}

}  // namespace imageio_detail

std::string MetaValue::to_text() const {
  if (kind == Kind::Text) return text;
  if (kind == Kind::Integer) return std::to_string(integer);
  return imageio_detail::exact_text(real);
}

namespace {

namespace fs = std::filesystem;
using namespace imageio_detail;

enum class Format { Hdf5, Fits, Exr, Png };

const char* const kAccepted = ".h5, .fits, .fit, .exr or .png";

// The format an extension names, compared without regard to case; false
// for anything else.
bool format_of(const std::string& path, Format& format) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".h5") format = Format::Hdf5;
  else if (ext == ".fits" || ext == ".fit") format = Format::Fits;
  else if (ext == ".exr") format = Format::Exr;
  else if (ext == ".png") format = Format::Png;
  else return false;
  return true;
}

std::string extension_of(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  return ext.empty() ? "none" : "'" + ext + "'";
}

// ------------------------------------------------------------- the rules

bool printable_ascii(const std::string& text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return c >= 32 && c <= 126; });
}

// 1 to 32 characters that are safe in an HDF5 attribute, a FITS string,
// an EXR channel name and a comma-separated list.
bool valid_band_name(const std::string& name) {
  static const std::regex pattern("[A-Za-z0-9_.+-]{1,32}");
  return std::regex_match(name, pattern);
}

bool valid_key(const std::string& key) {
  static const std::regex pattern("[A-Za-z][A-Za-z0-9_-]{0,23}");
  return std::regex_match(key, pattern);
}

// Names the layouts use themselves, in any case: the HDF5 attributes, and
// the FITS keywords that describe the array (a metadata keyword BSCALE would
// silently rescale every pixel when read) or that the layout writes.
bool reserved_key(const std::string& key) {
  std::string upper = key;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  static const std::set<std::string> names = {
      "BANDS",    "UNITS",    "EXPOSURE", "SCHEMA_VERSION", "SIMPLE",  "BITPIX",  "NAXIS",
      "EXTEND",   "BSCALE",   "BZERO",    "BLANK",          "BUNIT",   "END",     "COMMENT",
      "HISTORY",  "CONTINUE", "LONGSTRN", "HIERARCH",       "XTENSION", "PCOUNT", "GCOUNT",
      "GROUPS",   "CHECKSUM", "DATASUM",  "DATAMIN",        "DATAMAX", "SCENE_TOML", "EXTNAME"};
  static const std::regex numbered("(NAXIS|BAND)[0-9]+");
  return names.count(upper) > 0 || std::regex_match(upper, numbered);
}

bool trailing_blank(const std::string& text) { return !text.empty() && text.back() == ' '; }

// TEXT in quotes for a message, control and non-ASCII bytes as \xNN so
// the message stays one printable line.
std::string quoted(const std::string& text) {
  std::string out = "'";
  for (unsigned char c : text) {
    if (c >= 32 && c <= 126) {
      out += static_cast<char>(c);
    } else {
      char code[8];
      std::snprintf(code, sizeof code, "\\x%02X", c);
      out += code;
    }
  }
  return out + "'";
}

void check_image(const Image& image, const std::string& path, Format) {
  const std::string where = "cannot write " + path + ": ";
  if (image.width <= 0 || image.height <= 0)
    throw Error(where + "the image is " + std::to_string(image.width) + " x " +
                std::to_string(image.height) + " pixels (both must be positive)");
  if (image.bands.empty()) throw Error(where + "the image has no bands");
  if (image.pixels.size() != image.plane_size() * image.bands.size())
    throw Error(where + "the image holds " + std::to_string(image.pixels.size()) + " values, not " +
                std::to_string(image.width) + " x " + std::to_string(image.height) + " x " +
                std::to_string(image.bands.size()) + " bands");
  if (image.pixels.size() > kMaxElements)
    throw Error(where + "the image holds more than 2^29 values (the readers' limit)");
  std::set<std::string> seen;
  for (const std::string& band : image.bands) {
    if (!valid_band_name(band))
      throw Error(where + "band name " + quoted(band) + " is not 1 to 32 characters of [A-Za-z0-9_.+-]");
    if (!seen.insert(band).second) throw Error(where + "band " + band + " appears twice");
  }

  // Finite and non-negative: a NaN or a negative radiance is a bug upstream,
  // and a file is the worst place to discover it.
  for (size_t b = 0; b < image.bands.size(); ++b)
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const float v = image.at(static_cast<int>(b), x, y);
        if (std::isfinite(v) && v >= 0.0f) continue;
        const std::string pixel = "band " + image.bands[b] + ", pixel (x " + std::to_string(x) +
                                  ", y " + std::to_string(y) + ") is ";
        if (std::isnan(v)) throw Error(where + pixel + "NaN (no NaN in an output)");
        if (std::isinf(v)) throw Error(where + pixel + (v > 0 ? "+inf" : "-inf") + " (outputs must be finite)");
        char value[32];
        std::snprintf(value, sizeof value, "%g", v);
        throw Error(where + pixel + "negative (" + value + "; outputs must be non-negative)");
      }
}

void check_metadata(const ImageMetadata& m, const std::string& path) {
  const std::string where = "cannot write " + path + ": ";
  if (!std::isfinite(m.exposure) || m.exposure <= 0)
    throw Error(where + "exposure " + exact_text(m.exposure) + " must be finite and positive");
  if (m.scene_text.find('\0') != std::string::npos)
    throw Error(where + "the scene text holds a NUL byte");
  if (m.units.empty() || !printable_ascii(m.units) || trailing_blank(m.units))
    throw Error(where + "units " + quoted(m.units) +
                " must be non-empty printable ASCII without trailing blanks");
  std::set<std::string> seen;  // upper case: FITS keywords do not keep case
  for (const auto& [key, value] : m.entries) {
    if (!valid_key(key))
      throw Error(where + "metadata key " + quoted(key) +
                  " is not 1 to 24 characters of [A-Za-z0-9_-] starting with a letter");
    if (reserved_key(key))
      throw Error(where + "metadata key '" + key + "' is a name the file layouts use themselves");
    std::string upper = key;
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    if (!seen.insert(upper).second)
      throw Error(where + "metadata key '" + key + "' appears twice (keys are compared ignoring case)");
    if (value.is_number()) {
      // KEY = VALUE / nebula key: KEY on one FITS card: 51 + 2 x 14 <= 80.
      if (key.size() > 14)
        throw Error(where + "metadata key '" + key + "' holds a number: numeric keys have at most 14 characters");
      if (!std::isfinite(value.number()))
        throw Error(where + "metadata " + key + " = " + value.to_text() + " must be a finite number");
    } else if (!printable_ascii(value.text) || trailing_blank(value.text)) {
      throw Error(where + "metadata " + key + " = " + quoted(value.text) +
                  " must be printable ASCII without trailing blanks");
    }
  }
}

}  // namespace

void check_image_format(const std::string& path) {
  Format format{};
  if (!format_of(path, format))
    throw Error("cannot write " + path + ": unknown image extension " + extension_of(path) +
                " (expected " + kAccepted + ")");
  if ((format == Format::Exr || format == Format::Png) && !openimageio_available())
    throw Error("cannot write " + path + ": " + (format == Format::Exr ? ".exr" : ".png") +
                " output needs OpenImageIO; this build has none (configure with "
                "-DNEBULA_OPENIMAGEIO=ON), use .h5 or .fits");
}

std::vector<float> shown_channels(const Image& image, const std::vector<PngColour>& colours) {
  const int channels = image.bands.size() == 1 ? 1 : 3;
  const size_t plane = image.plane_size();
  std::vector<float> shown(plane * size_t(channels));
  for (size_t i = 0; i < plane; ++i)
    for (int c = 0; c < channels; ++c) {
      float v = 0.0f;
      for (size_t b = 0; b < colours.size(); ++b) {
        const PngColour& w = colours[b];
        v += (c == 0 ? w.red : c == 1 ? w.green : w.blue) * image.pixels[b * plane + i];
      }
      shown[size_t(c) * plane + i] = v;
    }
  return shown;
}

std::vector<PngColour> png_colours(const Image& image, const ImageMetadata& metadata) {
  const size_t n = image.bands.size();
  if (n == 1) return {PngColour{1, 1, 1}};
  std::vector<PngColour> out(n);
  if (std::set<std::string>(image.bands.begin(), image.bands.end()) == std::set<std::string>{"B", "V", "R"}) {
    for (size_t b = 0; b < n; ++b)
      out[b] = image.bands[b] == "R" ? PngColour{1, 0, 0} : image.bands[b] == "V" ? PngColour{0, 1, 0} : PngColour{0, 0, 1};
    return out;
  }
  std::vector<std::pair<double, size_t>> pivots;
  for (size_t b = 0; b < n; ++b) {
    // pivot_nm_<band>, or pivot_nm_b<plane> for a long band name (docs/image_files.md).
    const auto at = std::find_if(metadata.entries.begin(), metadata.entries.end(), [&](const auto& e) {
      return e.first == "pivot_nm_" + image.bands[b] || e.first == "pivot_nm_b" + std::to_string(b + 1);
    });
    if (at == metadata.entries.end() || !at->second.is_number() || !(at->second.number() > 0))
      throw Error("PNG needs bands B, V, R (shown as blue, green, red), a single band (grey), or a pivot "
                  "wavelength for every band (metadata pivot_nm_<band>) to colour them by; band " +
                  image.bands[b] + " of " + join_bands(image.bands) + " has none");
    pivots.push_back({at->second.number(), b});
  }
  std::sort(pivots.begin(), pivots.end());
  if (n == 2) {
    out[pivots[0].second] = {0.0f, 0.5f, 1.0f};
    out[pivots[1].second] = {1.0f, 0.5f, 0.0f};
    return out;
  }
  // Hue from 240 degrees (blue) for the shortest pivot down to 0 (red) for the
  // longest, on the piecewise-linear colour wheel (60 degrees per primary step).
  float sum[3] = {0, 0, 0};
  for (size_t r = 0; r < n; ++r) {
    const double hue = 240.0 * (1.0 - double(r) / double(n - 1));
    const auto ramp = [&](double centre) {
      const double d = std::fabs(hue - centre);
      return float(std::clamp(2.0 - d / 60.0, 0.0, 1.0));
    };
    PngColour c{ramp(0.0), ramp(120.0), ramp(240.0)};
    out[pivots[r].second] = c;
    sum[0] += c.red;
    sum[1] += c.green;
    sum[2] += c.blue;
  }
  for (PngColour& c : out) {
    c.red /= sum[0];
    c.green /= sum[1];
    c.blue /= sum[2];
  }
  return out;
}

void write_image(const Image& image, const std::string& path, const ImageMetadata& metadata,
                 bool overwrite) {
  check_image_format(path);
  Format format{};
  format_of(path, format);
  check_image(image, path, format);
  check_metadata(metadata, path);
  if (format == Format::Png) {
    try {
      png_colours(image, metadata);
    } catch (const Error& e) {
      throw Error("cannot write " + path + ": " + e.what());
    }
  }
  check_output_target(path, overwrite, "folder", true);

  TemporaryFile temporary(path);
  try {
    switch (format) {
      case Format::Hdf5: write_hdf5(image, metadata, temporary.path()); break;
      case Format::Fits: write_fits(image, metadata, temporary.path()); break;
      case Format::Exr: write_exr(image, metadata, temporary.path()); break;
      case Format::Png: write_png(image, metadata, temporary.path()); break;
    }
  } catch (const Error& e) {
    throw Error("cannot write " + path + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw Error("cannot write " + path + ": out of memory");
  }
  temporary.publish();
}

void write_cube(const std::vector<Image>& images, const std::vector<CubeAxis>& axes, const std::string& path,
                const ImageMetadata& metadata, bool overwrite) {
  check_image_format(path);
  Format format{};
  format_of(path, format);
  if (format != Format::Fits && format != Format::Hdf5)
    throw Error("cannot write " + path + ": a cube is written as .fits, .fit or .h5");
  size_t points = 1;
  for (const CubeAxis& a : axes) {
    if (a.values.empty()) throw Error("cannot write " + path + ": the axis " + a.key + " has no values");
    points *= a.values.size();
  }
  if (images.empty() || images.size() != points)
    throw Error("cannot write " + path + ": " + std::to_string(images.size()) + " images for " +
                std::to_string(points) + " grid points");
  for (const Image& image : images) {
    if (image.width != images.front().width || image.height != images.front().height ||
        image.bands != images.front().bands)
      throw Error("cannot write " + path + ": the cube's images differ in size or bands");
    check_image(image, path, format);
  }
  if (double(images.front().pixels.size()) * double(images.size()) > double(kMaxElements))
    throw Error("cannot write " + path + ": the cube holds more than 2^29 values (the readers' limit)");
  check_metadata(metadata, path);
  check_output_target(path, overwrite, "folder", true);
  std::vector<const Image*> list;
  for (const Image& image : images) list.push_back(&image);
  TemporaryFile temporary(path);
  try {
    if (format == Format::Fits)
      write_fits_cube(list, axes, metadata, temporary.path());
    else
      write_hdf5_cube(list, axes, metadata, temporary.path());
  } catch (const Error& e) {
    throw Error("cannot write " + path + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw Error("cannot write " + path + ": out of memory");
  }
  temporary.publish();
}

std::vector<Image> read_fits_cube(const std::string& path, std::vector<CubeAxis>* axes) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error(path + ": cannot read: no such file");
  return read_fits_cube_file(path, axes);
}

Image read_image(const std::string& path, ImageMetadata* metadata) {
  Format format{};
  if (!format_of(path, format))
    throw Error(path + ": cannot read: unknown image extension " + extension_of(path) +
                " (expected .h5, .fits, .fit or .exr)");
  if (format == Format::Png)
    throw Error(path + ": cannot read: a PNG is a tone-mapped 8-bit picture, not data; read the "
                ".h5, .fits or .exr");
  if (format == Format::Exr && !openimageio_available())
    throw Error(path + ": cannot read: .exr needs OpenImageIO; this build has none (configure "
                "with -DNEBULA_OPENIMAGEIO=ON)");

  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw Error(path + ": cannot read: no such file");
  if (fs::is_directory(status)) throw Error(path + ": cannot read: it is a folder");
  if (std::FILE* probe = std::fopen(path.c_str(), "rb")) {
    std::fclose(probe);
  } else {
    throw Error(path + ": cannot read: " + std::strerror(errno));
  }

  ImageMetadata read_metadata;
  Image image;
  try {
    switch (format) {
      case Format::Hdf5:
        hdf5io::read_in_child_first(path, [&] {
          ImageMetadata ignored;
          read_hdf5(path, &ignored);
        });
        image = read_hdf5(path, &read_metadata);
        break;
      case Format::Fits: image = read_fits(path, &read_metadata); break;
      case Format::Exr: image = read_exr(path, &read_metadata); break;
      case Format::Png: break;  // refused above
    }
  } catch (const std::bad_alloc&) {
    throw Error(path + ": out of memory while reading the image");
  }

  // What every format must give back: distinct, well-formed band names and
  // finite pixels.
  std::set<std::string> seen;
  for (const std::string& band : image.bands)
    if (!valid_band_name(band) || !seen.insert(band).second)
      fail(path, "bands", "distinct names of 1 to 32 characters of [A-Za-z0-9_.+-]",
           quoted(join_bands(image.bands)));
  for (size_t b = 0; b < image.bands.size(); ++b)
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (!std::isfinite(image.at(static_cast<int>(b), x, y)))
          fail(path, "pixels", "finite values",
               "a non-finite value in band " + image.bands[b] + " at (x " + std::to_string(x) +
                   ", y " + std::to_string(y) + ")");
  if (metadata != nullptr) *metadata = read_metadata;
  return image;
}

std::string variance_path(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + ".var";
  return path.substr(0, dot) + ".var" + path.substr(dot);
}

}  // namespace nebula
