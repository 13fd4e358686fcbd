// The FITS image file: one 3-D primary image, NAXIS1 = width, NAXIS2 =
// height, NAXIS3 = bands, BITPIX -32. FITS rows run bottom-up (pixel (1, 1)
// is the lower left corner as FITS viewers show it), so row y of an Image is
// FITS row NAXIS2 - y on both write and read. Keywords: BUNIT, BAND1..n,
// EXPOSURE, one keyword per metadata entry, CHECKSUM and DATASUM
// (docs/image_files.md).
#include <fitsio.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "core/error.h"
#include "imageio/image_formats.h"

namespace nebula::imageio_detail {

namespace {

// cfitsio is thread-safe only when built reentrant (Debian's is); images are
// written rarely, so one lock costs nothing and spares us the question.
std::mutex fits_mutex;

// The comment that marks a keyword as a metadata entry and keeps the key's
// case, which FITS keywords (upper case) lose.
const std::string kEntryMarker = "nebula key: ";

std::string cfitsio_reason(int status) {
  char text[FLEN_STATUS] = {0};
  fits_get_errstatus(status, text);
  fits_clear_errmsg();
  return "cfitsio: " + std::string(text);
}

// Closes the file on every path out; a write closes explicitly to see the
// status of the final flush.
struct FitsFile {
  fitsfile* f = nullptr;
  ~FitsFile() {
    if (f != nullptr) {
      int ignored = 0;
      fits_close_file(f, &ignored);
      fits_clear_errmsg();
    }
  }
};

std::string upper(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return text;
}

std::string trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(' ');
  if (begin == std::string::npos) return {};
  return text.substr(begin, text.find_last_not_of(' ') - begin + 1);
}

// The 80-character cards of KEYWORD = 'VALUE' / COMMENT. Keywords longer
// than 8 characters use the HIERARCH convention; values too long for one
// card continue on CONTINUE cards (long-string convention, FITS 4.0 section
// 4.2.1.2), each piece but the last ending in '&'. We build the cards
// ourselves because cfitsio's writer lets the value crowd the comment off
// the card, and the comment carries the metadata key: here it always ends
// the last card whole. cfitsio stops reading at an empty piece, so the last
// card always holds part of a non-empty value (metadata keys are short
// enough for an empty value and the comment to share one card).
std::vector<std::string> string_cards(const std::string& keyword, const std::string& value,
                                      const std::string& comment) {
  std::string prefix = keyword.size() <= 8 ? keyword + std::string(8 - keyword.size(), ' ') + "= "
                                           : "HIERARCH " + keyword + " = ";
  // Quotes are doubled inside FITS strings; a doubled quote is never split.
  std::vector<std::string> tokens;
  for (char c : value) tokens.push_back(c == '\'' ? "''" : std::string(1, c));
  const std::string tail = comment.empty() ? "" : " / " + comment;
  std::vector<std::string> cards;
  size_t next = 0;
  while (true) {
    const size_t room = 80 - prefix.size() - 2;  // between the quotes
    std::string rest;
    for (size_t i = next; i < tokens.size(); ++i) rest += tokens[i];
    if (rest.size() + tail.size() <= room || next + 1 >= tokens.size()) {
      cards.push_back(prefix + "'" + rest + "'" + tail);
      return cards;
    }
    std::string piece;  // may be empty on a crowded first card
    while (next + 1 < tokens.size() && piece.size() + tokens[next].size() + 1 <= room) piece += tokens[next++];
    cards.push_back(prefix + "'" + piece + "&'");
    prefix = "CONTINUE  ";
  }
}

// A numeric entry's card: KEYWORD = VALUE / nebula key: KEY on one card (the
// metadata rules keep numeric keys short enough). Reals are the shortest
// decimal that reads back exactly, with a point or exponent so FITS reads
// them as reals.
std::string number_card(const std::string& keyword, const MetaValue& value, const std::string& comment) {
  std::string text;
  if (value.kind == MetaValue::Kind::Integer) {
    text = std::to_string(value.integer);
  } else {
    text = exact_text(value.real);
    for (char& c : text)
      if (c == 'e') c = 'E';
    if (text.find_first_of(".E") == std::string::npos) text += ".0";
  }
  std::string card;
  if (keyword.size() <= 8) {
    card = keyword + std::string(8 - keyword.size(), ' ') + "= ";
    if (text.size() < 20) card += std::string(20 - text.size(), ' ');  // fixed format: right-justified to column 30
  } else {
    card = "HIERARCH " + keyword + " = ";
  }
  card += text + " / " + comment;
  if (card.size() > 80) throw Error("keyword " + keyword + ": value and key do not fit one card");
  return card;
}

// Reads one open file; every failure names the file and the keyword.
class Reader {
 public:
  Reader(const std::string& path, fitsfile* f) : path_(path), f_(f) {}

  // The value type of a keyword's first card: 'C' string, 'I' integer, 'F'
  // float, 'L' logical; '\0' when there is no such keyword.
  char type_of(const std::string& name) const {
    char card[FLEN_CARD] = {0}, value[FLEN_VALUE] = {0}, comment[FLEN_COMMENT] = {0};
    int status = 0;
    if (fits_read_card(f_, const_cast<char*>(name.c_str()), card, &status) != 0) {
      fits_clear_errmsg();
      return '\0';
    }
    char type = '\0';
    if (fits_parse_value(card, value, comment, &status) != 0 || value[0] == '\0' ||
        fits_get_keytype(value, &type, &status) != 0) {
      fits_clear_errmsg();
      return '?';
    }
    return type;
  }

  // A string keyword, continued or not, and the comment of its last card.
  std::string string_key(const std::string& name, const std::string& expected,
                         std::string* comment = nullptr) const {
    const char type = type_of(name);
    if (type == '\0') fail(path_, name, expected, "no such keyword (not a nebula image?)");
    if (type != 'C') fail(path_, name, expected, "a keyword that is not a string");
    char* text = nullptr;
    char last_comment[FLEN_COMMENT] = {0};
    int status = 0;
    if (fits_read_key_longstr(f_, const_cast<char*>(name.c_str()), &text, last_comment, &status) != 0)
      fail(path_, name, expected, cfitsio_reason(status));
    std::string value = text != nullptr ? text : "";
    if (text != nullptr) fits_free_memory(text, &status);
    if (comment != nullptr) *comment = trim(last_comment);
    return value;
  }

  double double_key(const std::string& name, const std::string& expected) const {
    const char type = type_of(name);
    if (type == '\0') fail(path_, name, expected, "no such keyword (not a nebula image?)");
    if (type != 'F' && type != 'I') fail(path_, name, expected, "a keyword that is not a number");
    double value = 0;
    int status = 0;
    if (fits_read_key_dbl(f_, const_cast<char*>(name.c_str()), &value, nullptr, &status) != 0)
      fail(path_, name, expected, cfitsio_reason(status));
    return value;
  }

  // The metadata entries, in header order: string keywords whose comment
  // carries the marker and the key, which must match the keyword.
  MetaEntries entries() const {
    int count = 0, status = 0;
    if (fits_get_hdrspace(f_, &count, nullptr, &status) != 0)
      fail(path_, "header", "a readable header", cfitsio_reason(status));
    MetaEntries found;
    for (int i = 1; i <= count; ++i) {
      char card[FLEN_CARD] = {0}, name[FLEN_KEYWORD] = {0};
      int length = 0;
      if (fits_read_record(f_, i, card, &status) != 0 ||
          fits_get_keyname(card, name, &length, &status) != 0)
        fail(path_, "header card " + std::to_string(i), "a readable card", cfitsio_reason(status));
      const std::string keyword = name;
      if (keyword.empty() || keyword == "COMMENT" || keyword == "HISTORY" || keyword == "CONTINUE") continue;
      const char type = type_of(keyword);
      std::string comment;
      MetaValue value;
      if (type == 'C') {
        value = string_key(keyword, "a string", &comment);
      } else if (type == 'I' || type == 'F') {
        char text[FLEN_VALUE] = {0}, note[FLEN_COMMENT] = {0};
        if (fits_parse_value(card, text, note, &status) != 0)
          fail(path_, keyword, "a readable number", cfitsio_reason(status));
        comment = trim(note);
        if (comment.rfind(kEntryMarker, 0) != 0) continue;
        if (type == 'I') {
          LONGLONG n = 0;
          if (fits_read_key_lnglng(f_, keyword.c_str(), &n, nullptr, &status) != 0)
            fail(path_, keyword, "an integer of 64 bits", cfitsio_reason(status));
          value = static_cast<long long>(n);
        } else {
          value = double_key(keyword, "a number");
        }
      } else {
        continue;
      }
      if (comment.rfind(kEntryMarker, 0) != 0) continue;
      const std::string key = comment.substr(kEntryMarker.size());
      if (upper(key) != keyword)
        fail(path_, keyword, "the comment '" + kEntryMarker + "KEY' with KEY matching the keyword",
             "'" + comment + "'");
      found.emplace_back(key, value);
    }
    return found;
  }

 private:
  const std::string& path_;
  fitsfile* f_;
};

}  // namespace

void write_fits(const Image& image, const ImageMetadata& metadata, const std::string& file_name) {
  write_fits_cube({&image}, {}, metadata, file_name);
}

void write_fits_cube(const std::vector<const Image*>& images, const std::vector<CubeAxis>& cube_axes,
                     const ImageMetadata& metadata, const std::string& file_name) {
  const Image& image = *images.front();
  const std::lock_guard<std::mutex> lock(fits_mutex);
  // cfitsio creates the file itself and refuses one that exists. Its
  // "disk file" calls take the name literally, where the plain ones would
  // parse brackets and a leading '!' as instructions.
  std::error_code ec;
  std::filesystem::remove(file_name, ec);
  FitsFile fits;
  int status = 0;
  if (fits_create_diskfile(&fits.f, const_cast<char*>(file_name.c_str()), &status) != 0) {
    fits.f = nullptr;
    throw Error("creating the FITS file (" + cfitsio_reason(status) + ")");
  }
  // NAXIS1..3 = width, height, bands; then the cube's axes, the last (the
  // fastest varying) first, so that numpy's shape is (first axis, ..., bands, rows, columns).
  std::vector<long> axes{image.width, image.height, static_cast<long>(image.bands.size())};
  for (size_t k = cube_axes.size(); k-- > 0;) axes.push_back(static_cast<long>(cube_axes[k].values.size()));
  if (fits_create_img(fits.f, FLOAT_IMG, static_cast<int>(axes.size()), axes.data(), &status) != 0)
    throw Error("creating the FITS image (" + cfitsio_reason(status) + ")");

  bool continued = false;
  auto write_string = [&](const std::string& keyword, const std::string& value, const std::string& comment) {
    const std::vector<std::string> cards = string_cards(keyword, value, comment);
    continued = continued || cards.size() > 1;
    for (const std::string& card : cards)
      if (fits_write_record(fits.f, card.c_str(), &status) != 0)
        throw Error("writing keyword " + keyword + " (" + cfitsio_reason(status) + ")");
  };
  write_string("BUNIT", metadata.units, "unit of the pixel values");
  for (size_t b = 0; b < image.bands.size(); ++b)
    write_string("BAND" + std::to_string(b + 1), image.bands[b], "band of image plane " + std::to_string(b + 1));
  // -17: seventeen significant digits, enough for any double to read back exactly.
  if (fits_write_key_dbl(fits.f, "EXPOSURE", metadata.exposure, -17,
                         "display scale before tone mapping (not a time)", &status) != 0)
    throw Error("writing keyword EXPOSURE (" + cfitsio_reason(status) + ")");
  for (const auto& [key, value] : metadata.entries) {
    if (!value.is_number()) {
      write_string(upper(key), value.text, kEntryMarker + key);
    } else if (fits_write_record(fits.f, number_card(upper(key), value, kEntryMarker + key).c_str(), &status) != 0) {
      throw Error("writing keyword " + upper(key) + " (" + cfitsio_reason(status) + ")");
    }
  }
  if (continued && fits_write_key_longwarn(fits.f, &status) != 0)
    throw Error("writing keyword LONGSTRN (" + cfitsio_reason(status) + ")");

  // Plane by plane, top row last (FITS rows go up).
  const size_t width = image.width, plane = image.plane_size();
  std::vector<float> rows(plane);
  size_t first = 1;
  for (const Image* each : images)
    for (size_t b = 0; b < image.bands.size(); ++b, first += plane) {
      for (int y = 0; y < image.height; ++y) {
        const float* source = &each->pixels[b * plane + size_t(y) * width];
        std::copy(source, source + width, rows.begin() + size_t(image.height - 1 - y) * width);
      }
      if (fits_write_img(fits.f, TFLOAT, static_cast<LONGLONG>(first), static_cast<LONGLONG>(plane), rows.data(),
                         &status) != 0)
        throw Error("writing the pixels (" + cfitsio_reason(status) + ")");
    }
  if (fits_write_chksum(fits.f, &status) != 0)
    throw Error("writing the checksums (" + cfitsio_reason(status) + ")");

  // The resolved scene: its bytes in a 1-D 8-bit image extension SCENE
  // (astropy: bytes(hdul["SCENE"].data).decode()).
  if (!metadata.scene_text.empty()) {
    long length[1] = {static_cast<long>(metadata.scene_text.size())};
    if (fits_create_img(fits.f, BYTE_IMG, 1, length, &status) != 0 ||
        fits_write_key_str(fits.f, "EXTNAME", "SCENE", "the resolved scene (TOML text, UTF-8 bytes)", &status) != 0 ||
        fits_write_img(fits.f, TBYTE, 1, static_cast<LONGLONG>(metadata.scene_text.size()),
                       const_cast<char*>(metadata.scene_text.data()), &status) != 0 ||
        fits_write_chksum(fits.f, &status) != 0)
      throw Error("writing the SCENE extension (" + cfitsio_reason(status) + ")");
  }
  // Each cube axis's values: a 1-D double image extension named by its key
  // (astropy: hdul["dust.albedo"].data).
  for (size_t k = 0; k < cube_axes.size(); ++k) {
    const CubeAxis& axis = cube_axes[k];
    long length[1] = {static_cast<long>(axis.values.size())};
    const int number = static_cast<int>(3 + cube_axes.size() - k);
    const std::string comment = "values along NAXIS" + std::to_string(number);
    if (fits_create_img(fits.f, DOUBLE_IMG, 1, length, &status) != 0 ||
        fits_write_key_str(fits.f, "EXTNAME", axis.key.c_str(), comment.c_str(), &status) != 0 ||
        fits_write_key_lng(fits.f, "AXISNUM", number, "the primary image's axis these values label", &status) != 0 ||
        fits_write_img(fits.f, TDOUBLE, 1, static_cast<LONGLONG>(axis.values.size()),
                       const_cast<double*>(axis.values.data()), &status) != 0 ||
        fits_write_chksum(fits.f, &status) != 0)
      throw Error("writing the extension " + axis.key + " (" + cfitsio_reason(status) + ")");
  }
  fitsfile* f = fits.f;
  fits.f = nullptr;
  if (fits_close_file(f, &status) != 0) throw Error("writing the FITS file (" + cfitsio_reason(status) + ")");
}

Image read_fits(const std::string& path, ImageMetadata* metadata) {
  const std::lock_guard<std::mutex> lock(fits_mutex);
  FitsFile fits;
  int status = 0;
  if (fits_open_diskfile(&fits.f, path.c_str(), READONLY, &status) != 0) {
    fits.f = nullptr;
    throw Error(path + ": cannot open as FITS (" + cfitsio_reason(status) + "); expected a nebula image");
  }
  const Reader r(path, fits.f);

  int bitpix = 0, naxis = 0;
  long axes[3] = {0, 0, 0};
  if (fits_get_img_param(fits.f, 3, &bitpix, &naxis, axes, &status) != 0)
    fail(path, "primary HDU", "an image", cfitsio_reason(status));
  if (naxis != 3) fail(path, "NAXIS", "3 (width, height, bands)", std::to_string(naxis));
  const std::string shape = std::to_string(axes[0]) + " x " + std::to_string(axes[1]) + " x " +
                            std::to_string(axes[2]);
  if (axes[0] <= 0 || axes[1] <= 0 || axes[2] <= 0 || axes[0] > INT_MAX || axes[1] > INT_MAX ||
      size_t(axes[2]) > kMaxElements / size_t(axes[0]) / size_t(axes[1]))
    fail(path, "NAXIS1..3", "an image of 1 to 2^29 values", shape);
  const size_t count = size_t(axes[0]) * size_t(axes[1]) * size_t(axes[2]);

  // The data must lie inside the file: a truncated file is refused before
  // a large allocation.
  LONGLONG header_start = 0, data_start = 0, data_end = 0;
  if (fits_get_hduaddrll(fits.f, &header_start, &data_start, &data_end, &status) != 0)
    fail(path, "primary HDU", "a readable header", cfitsio_reason(status));
  std::error_code ec;
  const auto file_size = std::filesystem::file_size(path, ec);
  if (!ec && size_t(data_start) + count * size_t(std::abs(bitpix) / 8) > file_size)
    fail(path, "data", shape + " pixels of BITPIX " + std::to_string(bitpix),
         "a file that ends early (truncated?)");

  // Files written here carry checksums; a mismatch means damage.
  int data_ok = 0, header_ok = 0;
  if (fits_verify_chksum(fits.f, &data_ok, &header_ok, &status) != 0)
    fail(path, "CHECKSUM", "a verifiable checksum", cfitsio_reason(status));
  // CHECKSUM covers header and data, so damaged pixels fail both: name the data.
  if (data_ok < 0) fail(path, "DATASUM", "the checksum of the pixels", "a mismatch (damaged file?)");
  if (header_ok < 0) fail(path, "CHECKSUM", "the checksum of the header", "a mismatch (damaged file?)");

  Image image;
  image.width = static_cast<int>(axes[0]);
  image.height = static_cast<int>(axes[1]);
  for (long b = 1; b <= axes[2]; ++b)
    image.bands.push_back(r.string_key("BAND" + std::to_string(b),
                                       "a string naming band " + std::to_string(b) + " of NAXIS3 = " +
                                           std::to_string(axes[2])));
  ImageMetadata m;
  m.units = r.string_key("BUNIT", "a string (the unit of the pixels)");
  m.exposure = r.double_key("EXPOSURE", "a number (the display scale)");
  if (!std::isfinite(m.exposure) || m.exposure <= 0)
    fail(path, "EXPOSURE", "a finite positive number", exact_text(m.exposure));
  m.entries = r.entries();

  // The scene text, when the file has the extension. A second HDU must pass
  // its checksums whatever it is; a foreign one is otherwise left alone.
  int hdus = 0;
  if (fits_get_num_hdus(fits.f, &hdus, &status) != 0) fail(path, "HDUs", "a readable file", cfitsio_reason(status));
  if (hdus < 2 && !ec && size_t(data_end) < file_size)
    fail(path, "HDU 2", "a readable extension after the primary HDU", "bytes that are none (damaged file?)");
  if (hdus >= 2) {
    int hdu_type = 0;
    if (fits_movabs_hdu(fits.f, 2, &hdu_type, &status) != 0)
      fail(path, "HDU 2", "a readable extension", cfitsio_reason(status));
    int data_ok = 0, header_ok = 0;
    if (fits_verify_chksum(fits.f, &data_ok, &header_ok, &status) != 0 || data_ok < 0 || header_ok < 0)
      fail(path, "HDU 2 CHECKSUM", "an extension with matching checksums", "a mismatch (damaged file?)");
    char extname[FLEN_VALUE] = {0};
    if (fits_read_key_str(fits.f, "EXTNAME", extname, nullptr, &status) != 0) {
      status = 0;
      fits_clear_errmsg();
    }
    if (std::string(extname) == "SCENE") {
      long length[1] = {0};
      int dims = 0, bits = 0;
      if (fits_get_img_param(fits.f, 1, &bits, &dims, length, &status) != 0 || bits != BYTE_IMG || dims != 1 ||
          length[0] <= 0 || size_t(length[0]) > kMaxElements)
        fail(path, "SCENE", "a 1-D 8-bit extension holding the scene text", "another shape");
      std::string text(size_t(length[0]), '\0');
      int any_null = 0;
      unsigned char no_null = 0;
      if (fits_read_img(fits.f, TBYTE, 1, length[0], &no_null, &text[0], &any_null, &status) != 0)
        fail(path, "SCENE", "readable scene text", cfitsio_reason(status));
      m.scene_text = text;
    }
    if (fits_movabs_hdu(fits.f, 1, nullptr, &status) != 0) fail(path, "primary HDU", "readable", cfitsio_reason(status));
  }

  image.pixels.resize(count);
  const size_t width = image.width, plane = image.plane_size();
  std::vector<float> rows(plane);
  for (size_t b = 0; b < image.bands.size(); ++b) {
    float no_null_check = 0;  // 0: values pass as stored, NaN included (refused by read_image)
    int any_null = 0;
    if (fits_read_img(fits.f, TFLOAT, static_cast<LONGLONG>(b * plane + 1), static_cast<LONGLONG>(plane),
                      &no_null_check, rows.data(), &any_null, &status) != 0)
      fail(path, "data", "readable pixels", cfitsio_reason(status));
    for (int y = 0; y < image.height; ++y) {
      const float* source = &rows[size_t(image.height - 1 - y) * width];
      std::copy(source, source + width, image.pixels.begin() + b * plane + size_t(y) * width);
    }
  }
  *metadata = m;
  return image;
}


std::vector<Image> read_fits_cube_file(const std::string& path, std::vector<CubeAxis>* cube_axes) {
  const std::lock_guard<std::mutex> lock(fits_mutex);
  FitsFile fits;
  int status = 0;
  if (fits_open_diskfile(&fits.f, path.c_str(), READONLY, &status) != 0) {
    fits.f = nullptr;
    throw Error(path + ": cannot open as FITS (" + cfitsio_reason(status) + "); expected a nebula cube");
  }
  const Reader r(path, fits.f);
  int bitpix = 0, naxis = 0;
  long axes[9] = {0};
  if (fits_get_img_param(fits.f, 9, &bitpix, &naxis, axes, &status) != 0)
    fail(path, "primary HDU", "an image", cfitsio_reason(status));
  if (naxis < 3 || naxis > 9) fail(path, "NAXIS", "3 to 9 (width, height, bands, the cube's axes)", std::to_string(naxis));
  size_t count = 1;
  for (int k = 0; k < naxis; ++k) {
    if (axes[k] <= 0 || size_t(axes[k]) > kMaxElements / count)
      fail(path, "NAXIS" + std::to_string(k + 1), "a cube of 1 to 2^29 values", std::to_string(axes[k]));
    count *= size_t(axes[k]);
  }
  int data_ok = 0, header_ok = 0;
  if (fits_verify_chksum(fits.f, &data_ok, &header_ok, &status) != 0 || data_ok < 0 || header_ok < 0)
    fail(path, "CHECKSUM", "matching checksums", "a mismatch (damaged file?)");
  Image shape;
  shape.width = static_cast<int>(axes[0]);
  shape.height = static_cast<int>(axes[1]);
  for (long b = 1; b <= axes[2]; ++b) shape.bands.push_back(r.string_key("BAND" + std::to_string(b), "a band name"));
  std::vector<float> all(count);
  int any_null = 0;
  float no_null = 0;
  if (fits_read_img(fits.f, TFLOAT, 1, static_cast<LONGLONG>(count), &no_null, all.data(), &any_null, &status) != 0)
    fail(path, "data", "readable pixels", cfitsio_reason(status));
  const size_t width = shape.width, plane = size_t(shape.width) * shape.height, per_image = plane * shape.bands.size();
  std::vector<Image> images(count / per_image, shape);
  for (size_t i = 0; i < images.size(); ++i) {
    images[i].pixels.resize(per_image);
    for (size_t b = 0; b < shape.bands.size(); ++b)
      for (int y = 0; y < shape.height; ++y) {  // FITS rows go up
        const float* row = &all[i * per_image + b * plane + size_t(shape.height - 1 - y) * width];
        std::copy(row, row + width, images[i].pixels.begin() + b * plane + size_t(y) * width);
      }
  }
  if (cube_axes) {
    cube_axes->clear();
    for (int k = naxis; k > 3; --k) {  // the first axis is the last FITS axis; keys from the extensions
      cube_axes->push_back({"", {}});
      cube_axes->back().values.resize(size_t(axes[k - 1]));
    }
    int hdus = 0;
    if (fits_get_num_hdus(fits.f, &hdus, &status) != 0) fail(path, "HDUs", "a readable file", cfitsio_reason(status));
    for (int h = 2; h <= hdus; ++h) {
      if (fits_movabs_hdu(fits.f, h, nullptr, &status) != 0)
        fail(path, "HDU " + std::to_string(h), "a readable extension", cfitsio_reason(status));
      long number = 0;
      if (fits_read_key_lng(fits.f, "AXISNUM", &number, nullptr, &status) != 0) {
        status = 0;
        fits_clear_errmsg();
        continue;
      }
      if (number < 4 || number > naxis) fail(path, "AXISNUM", "4 to NAXIS", std::to_string(number));
      CubeAxis& axis = (*cube_axes)[size_t(naxis - number)];
      char extname[FLEN_VALUE] = {0};
      if (fits_read_key_str(fits.f, "EXTNAME", extname, nullptr, &status) != 0)
        fail(path, "EXTNAME", "the key of axis " + std::to_string(number), cfitsio_reason(status));
      axis.key = extname;
      std::vector<double>& values = axis.values;
      double none = 0;
      if (fits_read_img(fits.f, TDOUBLE, 1, static_cast<LONGLONG>(values.size()), &none, values.data(), &any_null,
                        &status) != 0)
        fail(path, "AXIS" + std::to_string(number), "the axis's values", cfitsio_reason(status));
    }
  }
  if (cube_axes)
    for (const CubeAxis& a : *cube_axes)
      if (a.key.empty()) fail(path, "extensions", "one per cube axis (AXISNUM, EXTNAME)", "an axis without one");
  return images;
}

}  // namespace nebula::imageio_detail
