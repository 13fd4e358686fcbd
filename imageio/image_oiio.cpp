// EXR and PNG through OpenImageIO. EXR: one float32 channel per band,
// named by the band, zip-compressed (lossless), metadata as "nebula:..."
// attributes. PNG: 8-bit sRGB, tone-mapped by imageio/tone_map.h.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/error.h"
#include "imageio/image_formats.h"
#include "imageio/tone_map.h"

namespace nebula {

bool openimageio_available() { return true; }

Image read_any_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(path + ": cannot open as an image (" + imageio_detail::one_line_text(OIIO::geterror()) + ")");
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.deep || spec.depth != 1 || spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 ||
      size_t(spec.nchannels) > imageio_detail::kMaxElements / size_t(spec.width) / size_t(spec.height))
    throw Error(path + ": not a flat 2-D image of 1 to 2^29 values");
  const size_t plane = size_t(spec.width) * spec.height;
  std::vector<float> interleaved(plane * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, interleaved.data()))
    throw Error(path + ": cannot read the pixels (" + imageio_detail::one_line_text(in->geterror()) + ")");
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.bands = spec.channelnames;
  image.pixels.resize(plane * spec.nchannels);
  for (size_t c = 0; c < size_t(spec.nchannels); ++c)
    for (size_t i = 0; i < plane; ++i) {
      const float v = interleaved[i * spec.nchannels + c];
      if (!std::isfinite(v))
        throw Error(path + ": channel " + image.bands[c] + " at (x=" + std::to_string(i % spec.width) +
                    ", y=" + std::to_string(i / spec.width) + ") is not finite");
      image.pixels[c * plane + i] = v;
    }
  return image;
}

namespace imageio_detail {

std::string one_line_text(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

namespace {

// Attribute names. OpenEXR keeps attributes sorted by name and channels in
// its own order, so the band order and the entries' order are stored too.
const std::string kPrefix = "nebula:";
const std::string kEntryPrefix = "nebula:entry:";
const std::string kEntryOrder = "nebula:entry_order";
const std::string kChannels = "nebula:channels";

// The EXR channel of each band: with bands R, V and B present, those three
// are the channels R, G and B (viewers show colour); every other band is a
// one-channel layer "<band>.Y".
std::vector<std::string> exr_channels(const std::vector<std::string>& bands) {
  auto has = [&](const char* b) { return std::find(bands.begin(), bands.end(), b) != bands.end(); };
  const bool colour = has("R") && has("V") && has("B");
  std::vector<std::string> channels;
  for (const std::string& band : bands) {
    if (colour && band == "R") channels.push_back("R");
    else if (colour && band == "V") channels.push_back("G");
    else if (colour && band == "B") channels.push_back("B");
    else channels.push_back(band + ".Y");
  }
  return channels;
}

// OpenImageIO's messages may span lines; ours are one line.
std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? "no reason given" : text;
}

void add_metadata(OIIO::ImageSpec& spec, const ImageMetadata& m) {
  spec.attribute("Software", "nebula");
  spec.attribute(kPrefix + kSchemaName, kSchemaVersion);
  spec.attribute(kPrefix + kUnitsName, m.units);
  spec.attribute(kPrefix + kExposureName, exact_text(m.exposure));
  std::vector<std::string> keys;
  for (const auto& [key, value] : m.entries) {
    // OpenEXR has int (32-bit), double and string attributes; a larger
    // integer travels as a double.
    if (value.kind == MetaValue::Kind::Integer && value.integer == static_cast<int>(value.integer))
      spec.attribute(kEntryPrefix + key, static_cast<int>(value.integer));
    else if (value.is_number()) {
      const double number = value.number();
      spec.attribute(kEntryPrefix + key, OIIO::TypeDesc::DOUBLE, &number);
    }
    else
      spec.attribute(kEntryPrefix + key, value.text);
    keys.push_back(key);
  }
  spec.attribute(kEntryOrder, join_bands(keys));
  if (!m.scene_text.empty()) spec.attribute(kPrefix + "scene", m.scene_text);
}

void write_with(const char* format, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                const void* pixels, const std::string& file_name) {
  // By format name: the temporary file's extension is not the target's.
  auto out = OIIO::ImageOutput::create(format);
  if (!out) throw Error(std::string("OpenImageIO has no ") + format + " writer (" + one_line(OIIO::geterror()) + ")");
  if (!out->open(file_name, spec)) throw Error("OpenImageIO: " + one_line(out->geterror()));
  if (!out->write_image(type, pixels)) throw Error("OpenImageIO: " + one_line(out->geterror()));
  if (!out->close()) throw Error("OpenImageIO: " + one_line(out->geterror()));
}

}  // namespace

void write_exr(const Image& image, const ImageMetadata& metadata, const std::string& file_name) {
  const int channels = static_cast<int>(image.bands.size());
  OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::FLOAT);
  spec.channelnames = exr_channels(image.bands);
  spec.attribute("compression", "zip");
  spec.attribute(kPrefix + kBandsName, join_bands(image.bands));
  spec.attribute(kChannels, join_bands(spec.channelnames));
  add_metadata(spec, metadata);
  // OpenImageIO takes pixels interleaved; ours are planes.
  const size_t plane = image.plane_size();
  std::vector<float> interleaved(image.pixels.size());
  for (size_t i = 0; i < plane; ++i)
    for (int c = 0; c < channels; ++c) interleaved[i * channels + c] = image.pixels[c * plane + i];
  write_with("openexr", spec, OIIO::TypeDesc::FLOAT, interleaved.data(), file_name);
}

void write_png(const Image& image, const ImageMetadata& metadata, const std::string& file_name) {
  // Grey from a single band, else red, green, blue as weighted sums of the
  // bands (png_colours: R, V, B themselves, or hues by pivot wavelength).
  const std::vector<PngColour> colours = png_colours(image, metadata);
  const int channels = image.bands.size() == 1 ? 1 : 3;
  OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute(kPrefix + kBandsName, join_bands(image.bands));
  const DisplaySettings& display = metadata.display;
  // The channels shown (weighted sums of the bands), then the display transform;
  // auto exposure looks at the channels shown.
  const size_t plane = image.plane_size();
  const std::vector<float> shown = shown_channels(image, colours);
  const double exposure = display.auto_exposure ? auto_exposure_of(shown, display, metadata.exposure) : metadata.exposure;
  spec.attribute("nebula:tone_map", std::string(to_string(display.stretch)) + " stretch of value x exposure " +
                                        exact_text(exposure) + (display.auto_exposure ? " (auto)" : "") +
                                        " / white " + exact_text(display.white) + ", softening " +
                                        exact_text(display.softening) + ", clamped to [0, 1], sRGB curve (IEC 61966-2-1)");
  add_metadata(spec, metadata);
  std::vector<uint8_t> levels(plane * channels);
  for (size_t i = 0; i < plane; ++i)
    for (int c = 0; c < channels; ++c)
      levels[i * channels + c] = display_level(shown[size_t(c) * plane + i], exposure, display);
  write_with("png", spec, OIIO::TypeDesc::UINT8, levels.data(), file_name);
}

Image read_exr(const std::string& path, ImageMetadata* metadata) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(path + ": cannot open as EXR (" + one_line(OIIO::geterror()) + ")");
  if (std::string(in->format_name()) != "openexr")
    throw Error(path + ": not an EXR file (OpenImageIO reads it as " + in->format_name() + ")");
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.deep) fail(path, "image", "a flat image", "a deep image");
  const std::string shape = std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                            " x " + std::to_string(spec.nchannels);
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1 ||
      size_t(spec.nchannels) > kMaxElements / size_t(spec.width) / size_t(spec.height))
    fail(path, "image", "a 2-D image of 1 to 2^29 values", shape);

  const size_t plane = size_t(spec.width) * spec.height;
  std::vector<float> interleaved(plane * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, interleaved.data()))
    fail(path, "pixels", "readable pixels", "OpenImageIO: " + one_line(in->geterror()));

  // Our band order, whatever order the file keeps its channels in; the
  // channel of each band (schema 2: R, G, B for the bands R, V, B).
  std::vector<std::string> bands = spec.channelnames, channels = spec.channelnames;
  const std::string stored = spec.get_string_attribute(kPrefix + kBandsName);
  if (!stored.empty()) {
    bands = split_bands(stored);
    const std::string stored_channels = spec.get_string_attribute(kChannels);
    channels = stored_channels.empty() ? bands : split_bands(stored_channels);
    if (channels.size() != bands.size())
      fail(path, kChannels, "one channel per band of " + stored, "'" + stored_channels + "'");
    std::vector<std::string> a = channels, b = spec.channelnames;
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    if (a != b)
      fail(path, kPrefix + kBandsName, "the channel names in some order",
           "'" + stored + "' for channels " + join_bands(spec.channelnames));
  }
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.bands = bands;
  image.pixels.resize(plane * bands.size());
  for (size_t b = 0; b < bands.size(); ++b) {
    const size_t c = std::find(spec.channelnames.begin(), spec.channelnames.end(), channels[b]) -
                     spec.channelnames.begin();
    for (size_t i = 0; i < plane; ++i) image.pixels[b * plane + i] = interleaved[i * spec.nchannels + c];
  }

  // Any EXR is accepted; what it lacks keeps ImageMetadata's defaults. One
  // of ours from a newer layout is refused.
  const int schema = spec.get_int_attribute(kPrefix + kSchemaName, kSchemaVersion);
  if (schema != 1 && schema != kSchemaVersion)
    fail(path, kPrefix + kSchemaName, "1 or 2 (the image schemas this reader knows)", std::to_string(schema));
  ImageMetadata m;
  m.units = spec.get_string_attribute(kPrefix + kUnitsName, m.units);
  const std::string exposure = spec.get_string_attribute(kPrefix + kExposureName);
  if (!exposure.empty() && (!parse_double(exposure, m.exposure) || !(m.exposure > 0) || !std::isfinite(m.exposure)))
    fail(path, kPrefix + kExposureName, "a finite positive number", "'" + exposure + "'");
  const std::string order = spec.get_string_attribute(kEntryOrder);
  if (!order.empty())
    for (const std::string& key : split_bands(order)) {
      // OpenImageIO writes no attribute for an empty string: a listed entry
      // without one is empty.
      const OIIO::ParamValue* p = spec.find_attribute(kEntryPrefix + key);
      if (p == nullptr || p->type() == OIIO::TypeDesc::STRING)
        m.entries.emplace_back(key, p != nullptr ? p->get_string() : std::string());
      else if (p->type() == OIIO::TypeDesc::INT)
        m.entries.emplace_back(key, p->get_int());
      else if (p->type() == OIIO::TypeDesc::DOUBLE || p->type() == OIIO::TypeDesc::FLOAT)
        m.entries.emplace_back(key, p->type() == OIIO::TypeDesc::DOUBLE ? *static_cast<const double*>(p->data())
                                                                      : double(p->get_float()));
      else
        fail(path, kEntryPrefix + key, "a string, int or double attribute",
             "an attribute of type " + std::string(p->type().c_str()));
    }
  m.scene_text = spec.get_string_attribute(kPrefix + "scene");
  *metadata = m;
  return image;
}

}  // namespace imageio_detail

}  // namespace nebula
