#pragma once
// Rendered images to and from files (DESIGN.md section 4): linear float per
// band to HDF5, FITS and EXR, tone-mapped sRGB to PNG. Layouts, orientation
// and the tone curve are in docs/image_files.md.
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/display.h"
#include "core/image.h"

namespace nebula {

// A metadata value: text, an integer or a real number. Numbers travel as
// numbers (FITS numeric keywords, HDF5 int64/float64 attributes, EXR int and
// double attributes) so that astropy, h5py and the like read them as such.
struct MetaValue {
  enum class Kind { Text, Integer, Real };
  Kind kind = Kind::Text;
  std::string text;
  long long integer = 0;
  double real = 0;

  MetaValue() = default;
  MetaValue(std::string value) : text(std::move(value)) {}
  MetaValue(const char* value) : text(value) {}
  MetaValue(double value) : kind(Kind::Real), real(value) {}
  MetaValue(float value) : MetaValue(double(value)) {}
  template <class I, std::enable_if_t<std::is_integral_v<I> && !std::is_same_v<I, bool>, int> = 0>
  MetaValue(I value) : kind(Kind::Integer), integer(static_cast<long long>(value)) {}
  MetaValue(bool) = delete;  // say what a flag means: an integer 0/1 or a word

  bool is_number() const { return kind != Kind::Text; }
  double number() const { return kind == Kind::Integer ? double(integer) : real; }
  // The value as text: the text itself, or the shortest exact decimal.
  std::string to_text() const;
  bool operator==(const MetaValue& o) const {
    return kind == o.kind && (kind == Kind::Text ? text == o.text
                              : kind == Kind::Integer ? integer == o.integer
                                                      : (real == o.real || (real != real && o.real != o.real)));
  }
  bool operator!=(const MetaValue& o) const { return !(*this == o); }
};
using MetaEntries = std::vector<std::pair<std::string, MetaValue>>;

// What a file says besides its pixels. Keys are 1 to 24 characters of
// [A-Za-z0-9_-] starting with a letter, unique ignoring case (FITS keywords
// are upper case) and not one of the names the layouts use themselves;
// text values are printable ASCII without trailing blanks (FITS headers are
// ASCII and drop trailing blanks), numbers finite; units the same as text
// and not empty. Within these rules every format gives back exactly what was
// written, numbers as numbers of the same kind.
struct ImageMetadata {
  std::string units = "arbitrary";
  MetaEntries entries;  // e.g. {"albedo_B", 0.6}, {"camera_kind", "perspective"}
  // PNG: scale applied before tone mapping. The science formats record it
  // and leave the pixels alone: a display setting, not part of the data.
  double exposure = 1.0;
  double gamma = 2.2;     // unused by the writers: PNG uses the sRGB curve (README)
  // PNG only: stretch, white point, auto exposure (core/display.h). Science
  // formats neither apply nor record it.
  DisplaySettings display;
  // The resolved scene (TOML text) the image was made from, or empty. Any
  // bytes but NUL; FITS keeps it in an extension SCENE, HDF5 in the
  // attribute scene_toml, EXR in nebula:scene.
  std::string scene_text;
};

// Writes IMAGE to PATH in the format its extension names: .h5, .fits or
// .fit, .exr, .png (the last two only when built with OpenImageIO). Refuses,
// with one line naming the path and the reason and before touching the
// disk: an unknown extension, a malformed image or metadata, a NaN,
// infinite or negative pixel, a missing folder, an existing file unless
// `overwrite`. The file is written to a temporary name beside PATH and
// renamed into place, so no half-written file is ever seen or left behind.
void write_image(const Image& image, const std::string& path, const ImageMetadata& metadata,
                 bool overwrite);

// A cube of images over a grid of parameters (`nebula sweep`): one image per
// grid point, all of one size and bands, the first axis varying slowest.
struct CubeAxis {
  std::string key;             // e.g. "dust.albedo"
  std::vector<double> values;  // along the axis
};

// Writes the cube to PATH, .fits/.fit or .h5, with write_image's checks and
// atomic replacement. FITS: NAXIS = 3 + K, NAXIS1..3 the image's width,
// height and bands, then the axes last to first (numpy's shape: (first axis,
// ..., bands, rows, columns)), and one 1-D extension per axis named by its
// key holding its values. HDF5: /image of shape (axes..., bands, rows,
// columns), /axes/<key> the values, root attribute "axes" the keys in order.
// The metadata is the whole cube's (what all points share).
void write_cube(const std::vector<Image>& images, const std::vector<CubeAxis>& axes, const std::string& path,
                const ImageMetadata& metadata, bool overwrite);

// Reads a FITS cube written by write_cube: the images, first axis slowest,
// and the axes with their values. Errors name the file and the field.
std::vector<Image> read_fits_cube(const std::string& path, std::vector<CubeAxis>* axes = nullptr);

// write_image's first check, for callers that refuse a path before any work:
// an unknown extension, or .exr/.png in a build without OpenImageIO.
void check_image_format(const std::string& path);

// Reads an image written by write_image (.h5, .fits/.fit, and .exr with
// OpenImageIO), filling *metadata when given (gamma is not stored and stays
// at its default). Refuses missing, foreign, truncated or malformed files and
// non-finite pixels with one line naming the file and the field.
Image read_image(const std::string& path, ImageMetadata* metadata = nullptr);

// Reads any image OpenImageIO can open (PNG, TIFF, JPEG, EXR, ...) as float
// planes, for data such as axial maps (docs/axial.md): channels named as
// the file names them (R, G, B, A; Y for a single grey channel), integer
// formats scaled to [0, 1] by OpenImageIO, row 0 at the top. Refuses, with
// one line naming the file: a build without OpenImageIO, an unreadable or
// deep or 3-D image, non-finite values.
Image read_any_image(const std::string& path);

// How a PNG shows an image's bands (docs/image_files.md, "PNG"): per band, the
// weights of its plane in red, green and blue. One band: grey. Bands B, V, R:
// red, green, blue from R, V, B. Otherwise every band needs a pivot wavelength
// in the metadata (entry pivot_nm_<band>, as rendered images carry): the bands
// ranked by pivot take hues from blue (the shortest) to red (the longest),
// evenly by rank; with two bands, blue and red, and green their mean. Each
// channel's weights sum to 1, so equal planes show grey. Error (one line, the
// bands named) when neither rule applies.
struct PngColour {
  float red = 0, green = 0, blue = 0;
};
std::vector<PngColour> png_colours(const Image& image, const ImageMetadata& metadata);
// The channels shown (1 for a single band, else red, green, blue), plane by
// plane: each the weighted sum of the bands by `colours` (PNG and the viewer).
std::vector<float> shown_channels(const Image& image, const std::vector<PngColour>& colours);

// Where the variance of an image lives (the ground truth writes one beside its
// image; comparisons look for it): "out.h5" -> "out.var.h5".
std::string variance_path(const std::string& image_path);

// Whether this build has OpenImageIO, and so .exr and .png.
bool openimageio_available();

}  // namespace nebula
