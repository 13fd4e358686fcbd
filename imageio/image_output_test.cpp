#include "imageio/image_output.h"

#include <fitsio.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/test_support.h"
#include "imageio/tone_map.h"

#ifdef NEBULA_HAVE_OIIO
#include <OpenImageIO/imageio.h>
#endif

namespace nebula {
namespace {

namespace fs = std::filesystem;
using testing::expect_error;

// ------------------------------------------------------------- helpers

// Every value distinct, so a swapped band, row or column shows; the top-left
// pixel of each band stands out, and the first band holds values whose bits
// must survive exactly (subnormal, -0, largest float, odd last mantissa bit).
Image make_image(int width, int height, std::vector<std::string> bands = {"B", "V", "R"}) {
  Image image(width, height, std::move(bands));
  for (int b = 0; b < static_cast<int>(image.bands.size()); ++b)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) image.at(b, x, y) = 0.1f * (1 + b) + 0.01f * y + 0.001f * x;
  for (int b = 0; b < static_cast<int>(image.bands.size()); ++b) image.at(b, 0, 0) = 7777.0f + b;
  if (width >= 5) {
    image.at(0, 1, 0) = 1e-40f;
    image.at(0, 2, 0) = -0.0f;
    image.at(0, 3, 0) = FLT_MAX;
    image.at(0, 4, 0) = std::nextafter(1.0f, 2.0f);
  }
  return image;
}

ImageMetadata make_metadata() {
  ImageMetadata m;
  m.units = "W m-2 sr-1";
  m.exposure = 0.1;  // not exact in binary: must still come back bit for bit
  m.entries = {
      {"albedo_B", "0.6"},
      {"g", "0.6"},
      {"camera", "perspective fov 45 deg, eye (0, 0, -10), target (0, 0, 0), up (0, 1, 0); "
                 "it's 'quoted', & long enough to need several FITS cards of 80 characters each"},
      {"key_longer_than_8", "HIERARCH in FITS"},
      {"Mixed-Case_key", "  leading blanks are kept"},
      {"empty", ""},
      {"ends_in_mark", "value&"},
      {"int_key", 42},
      {"NEG_INT", -1234567890},
      {"real_key", 0.1},
      {"tiny_real", 2.2250738585072014e-308},
      {"whole_real", 3.0},
      {"CRPIX1", -1.5e300},
  };
  m.scene_text = "[camera]\nkind = \"perspective\"  # a comment, 'quotes', \u00e9\n\ttab\n";
  return m;
}

void expect_same_bits(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.bands, b.bands);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)), 0)
      << "pixels differ";
}

void expect_same_metadata(const ImageMetadata& a, const ImageMetadata& b) {
  EXPECT_EQ(a.units, b.units);
  EXPECT_EQ(a.exposure, b.exposure);
  ASSERT_EQ(a.entries.size(), b.entries.size());
  for (size_t i = 0; i < a.entries.size(); ++i) {
    EXPECT_EQ(a.entries[i].first, b.entries[i].first);
    EXPECT_TRUE(a.entries[i].second == b.entries[i].second)
        << a.entries[i].first << ": wrote " << a.entries[i].second.to_text() << " (kind "
        << int(a.entries[i].second.kind) << "), read " << b.entries[i].second.to_text() << " (kind "
        << int(b.entries[i].second.kind) << ")";
  }
  EXPECT_EQ(a.scene_text, b.scene_text);
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Each test works in its own fresh folder.
class ImageFile : public ::testing::Test, protected testing::ScratchDir {
 protected:
  ImageFile() : ScratchDir("nebula_imageio") {}
};

// ------------------------------------------------------------- round trips

TEST_F(ImageFile, Hdf5RoundTripIsExact) {
  const Image image = make_image(7, 5);
  const ImageMetadata metadata = make_metadata();
  write_image(image, path("a.h5"), metadata, false);
  ImageMetadata read_metadata;
  expect_same_bits(image, read_image(path("a.h5"), &read_metadata));
  expect_same_metadata(metadata, read_metadata);
  EXPECT_EQ(files(), std::vector<std::string>{"a.h5"});  // no temporary left
}

// A 3 x 2 cube: each point's image distinct (scaled), read back point by
// point with its axes; HDF5 with /image of shape (3, 2, bands, rows, columns)
// and the axes' values.
TEST_F(ImageFile, CubesRoundTripWithTheirAxes) {
  std::vector<Image> images;
  for (int k = 0; k < 6; ++k) {
    Image image = make_image(7, 5);
    for (float& v : image.pixels) v = v / float(k + 1) + float(k);
    images.push_back(image);
  }
  const std::vector<CubeAxis> axes{{"dust.albedo", {0.3, 0.6, 0.9}}, {"dust.g", {0.0, 0.75}}};
  write_cube(images, axes, path("c.fits"), make_metadata(), false);
  std::vector<CubeAxis> read_axes;
  const std::vector<Image> back = read_fits_cube(path("c.fits"), &read_axes);
  ASSERT_EQ(back.size(), 6u);
  for (int k = 0; k < 6; ++k) expect_same_bits(images[k], back[k]);
  ASSERT_EQ(read_axes.size(), 2u);
  for (int a = 0; a < 2; ++a) {
    EXPECT_EQ(read_axes[a].key, axes[a].key);
    EXPECT_EQ(read_axes[a].values, axes[a].values);
  }
  write_cube(images, axes, path("c.h5"), make_metadata(), false);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fopen(path("c.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t set = H5Dopen2(file, "/image", H5P_DEFAULT);
  const hid_t space = H5Dget_space(set);
  hsize_t dims[5] = {0};
  ASSERT_EQ(H5Sget_simple_extent_ndims(space), 5);
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ((std::vector<hsize_t>(dims, dims + 5)), (std::vector<hsize_t>{3, 2, 3, 5, 7}));
  std::vector<float> all(3 * 2 * 3 * 5 * 7);
  ASSERT_GE(H5Dread(set, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()), 0);
  EXPECT_EQ(std::vector<float>(all.begin() + 5 * 105, all.begin() + 6 * 105), images[5].pixels);
  const hid_t g = H5Dopen2(file, "/axes/dust.g", H5P_DEFAULT);
  double values[2] = {0, 0};
  ASSERT_GE(H5Dread(g, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values), 0);
  EXPECT_EQ(values[1], 0.75);
  H5Dclose(g);
  H5Sclose(space);
  H5Dclose(set);
  H5Fclose(file);
  // Refusals: too few images, an empty axis, a PNG.
  EXPECT_THROW(write_cube({images[0]}, axes, path("d.fits"), make_metadata(), false), Error);
  EXPECT_THROW(write_cube(images, {{"dust.g", {}}}, path("d.fits"), make_metadata(), false), Error);
  EXPECT_THROW(write_cube(images, axes, path("d.png"), make_metadata(), false), Error);
  EXPECT_FALSE(std::filesystem::exists(path("d.fits")));
}

TEST_F(ImageFile, Hdf5LayoutAsDocumented) {
  const Image image = make_image(7, 5);
  write_image(image, path("a.h5"), make_metadata(), false);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fopen(path("a.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t set = H5Dopen2(file, "/image", H5P_DEFAULT);
  const hid_t space = H5Dget_space(set);
  hsize_t dims[3] = {0, 0, 0};
  EXPECT_EQ(H5Sget_simple_extent_ndims(space), 3);
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], 3u);  // bands
  EXPECT_EQ(dims[1], 5u);  // height
  EXPECT_EQ(dims[2], 7u);  // width
  const hid_t type = H5Dget_type(set);
  EXPECT_TRUE(H5Tequal(type, H5T_IEEE_F32LE) > 0);
  std::vector<float> raw(3 * 5 * 7);
  H5Dread(set, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw.data());
  EXPECT_EQ(raw[0], 7777.0f);          // first element: band B, top-left
  EXPECT_EQ(raw[35], 7778.0f);         // band V starts after one plane
  EXPECT_EQ(raw[7], image.at(0, 0, 1));  // second row
  const hid_t bands = H5Aopen(file, "bands", H5P_DEFAULT);
  const hid_t bands_type = H5Aget_type(bands);
  // Schema 2: an array of three fixed-length strings, as h5py reads a list.
  const size_t size = H5Tget_size(bands_type);
  std::vector<char> text(3 * size + 1, '\0');
  H5Aread(bands, bands_type, text.data());
  EXPECT_STREQ(text.data(), "B");
  EXPECT_STREQ(text.data() + size, "V");
  EXPECT_STREQ(text.data() + 2 * size, "R");
  const hid_t albedo = H5Aopen(file, "albedo_B", H5P_DEFAULT);  // a string entry in make_metadata
  const hid_t albedo_type = H5Aget_type(albedo);
  EXPECT_EQ(H5Tget_class(albedo_type), H5T_STRING);
  H5Tclose(albedo_type);
  H5Aclose(albedo);
  const hid_t real = H5Aopen(file, "real_key", H5P_DEFAULT);  // a number entry: float64
  const hid_t real_type = H5Aget_type(real);
  EXPECT_TRUE(H5Tequal(real_type, H5T_IEEE_F64LE) > 0);
  double value = 0;
  H5Aread(real, H5T_NATIVE_DOUBLE, &value);
  EXPECT_EQ(value, 0.1);
  H5Tclose(real_type);
  H5Aclose(real);
  const hid_t whole = H5Aopen(file, "int_key", H5P_DEFAULT);  // an integer entry: int64
  const hid_t whole_type = H5Aget_type(whole);
  EXPECT_TRUE(H5Tequal(whole_type, H5T_STD_I64LE) > 0);
  H5Tclose(whole_type);
  H5Aclose(whole);
  EXPECT_GT(H5Aexists(file, "albedo_B"), 0);
  EXPECT_GT(H5Aexists(file, "schema_version"), 0);
  H5Tclose(bands_type);
  H5Aclose(bands);
  H5Tclose(type);
  H5Sclose(space);
  H5Dclose(set);
  H5Fclose(file);
}

TEST_F(ImageFile, FitsRoundTripIsExact) {
  const Image image = make_image(7, 5);
  const ImageMetadata metadata = make_metadata();
  for (const char* name : {"a.fits", "b.fit", "c.FITS"}) {
    write_image(image, path(name), metadata, false);
    ImageMetadata read_metadata;
    expect_same_bits(image, read_image(path(name), &read_metadata));
    expect_same_metadata(metadata, read_metadata);
  }
  EXPECT_EQ(files(), (std::vector<std::string>{"a.fits", "b.fit", "c.FITS"}));
}

TEST_F(ImageFile, SingleBandRoundTrips) {
  const Image image = make_image(3, 2, {"V"});
  for (const char* name : {"a.h5", "a.fits"}) {
    write_image(image, path(name), ImageMetadata{}, false);
    ImageMetadata m;
    expect_same_bits(image, read_image(path(name), &m));
    expect_same_metadata(ImageMetadata{}, m);
  }
}

// FITS rows go up: the image's top row is the last FITS row, and the
// header carries the documented keywords.
TEST_F(ImageFile, FitsLayoutAsDocumented) {
  const Image image = make_image(7, 5);
  write_image(image, path("a.fits"), make_metadata(), false);
  fitsfile* f = nullptr;
  int status = 0;
  ASSERT_EQ(fits_open_diskfile(&f, path("a.fits").c_str(), READONLY, &status), 0);
  int bitpix = 0, naxis = 0;
  long axes[3] = {0, 0, 0};
  fits_get_img_param(f, 3, &bitpix, &naxis, axes, &status);
  EXPECT_EQ(bitpix, -32);
  EXPECT_EQ(naxis, 3);
  EXPECT_EQ(axes[0], 7);
  EXPECT_EQ(axes[1], 5);
  EXPECT_EQ(axes[2], 3);
  float value = 0;
  long top_left[3] = {1, 5, 1}, bottom_left[3] = {1, 1, 1}, v_top_left[3] = {1, 5, 2};
  fits_read_pix(f, TFLOAT, top_left, 1, nullptr, &value, nullptr, &status);
  EXPECT_EQ(value, 7777.0f);
  fits_read_pix(f, TFLOAT, bottom_left, 1, nullptr, &value, nullptr, &status);
  EXPECT_EQ(value, image.at(0, 0, 4));
  fits_read_pix(f, TFLOAT, v_top_left, 1, nullptr, &value, nullptr, &status);
  EXPECT_EQ(value, 7778.0f);

  char text[FLEN_VALUE] = {0};
  fits_read_key_str(f, "BUNIT", text, nullptr, &status);
  EXPECT_STREQ(text, "W m-2 sr-1");
  fits_read_key_str(f, "BAND3", text, nullptr, &status);
  EXPECT_STREQ(text, "R");
  fits_read_key_str(f, "ALBEDO_B", text, nullptr, &status);  // the key, upper case
  EXPECT_STREQ(text, "0.6");
  fits_read_key_str(f, "KEY_LONGER_THAN_8", text, nullptr, &status);
  EXPECT_STREQ(text, "HIERARCH in FITS");
  double exposure = 0;
  fits_read_key_dbl(f, "EXPOSURE", &exposure, nullptr, &status);
  EXPECT_EQ(exposure, 0.1);
  int data_ok = 0, header_ok = 0;
  fits_verify_chksum(f, &data_ok, &header_ok, &status);
  EXPECT_EQ(data_ok, 1);
  EXPECT_EQ(header_ok, 1);
  EXPECT_EQ(status, 0);
  fits_close_file(f, &status);

  // The long camera entry continues over CONTINUE cards; keyword names are
  // upper case and the comment keeps the key as given.
  const std::string header = file_bytes(path("a.fits")).substr(0, 2880 * 2);
  EXPECT_NE(header.find("CAMERA  = '"), std::string::npos);
  EXPECT_NE(header.find("CONTINUE  '"), std::string::npos);
  EXPECT_NE(header.find("HIERARCH KEY_LONGER_THAN_8 = 'HIERARCH in FITS' / nebula key: key_longer_than_8"),
            std::string::npos);
  EXPECT_NE(header.find("/ nebula key: Mixed-Case_key"), std::string::npos);
}

// Keys of every length and values of every length and content come back
// exactly, however the cards split.
TEST_F(ImageFile, FitsStringsOfEveryShapeRoundTrip) {
  std::mt19937 rng(11);
  const std::string alphabet = "ab '&/=xyzXYZ019-_ ";
  ImageMetadata m;
  for (int i = 0; i < 120; ++i) {
    std::string key = "k";
    key += std::to_string(i) + "_" + std::string(rng() % 20, 'q');
    key.resize(std::min<size_t>(key.size(), 24));
    std::string value;
    const size_t length = i < 80 ? i * 3 : rng() % 400;
    for (size_t c = 0; c < length; ++c) value += alphabet[rng() % alphabet.size()];
    while (!value.empty() && value.back() == ' ') value.pop_back();
    m.entries.emplace_back(key, value);
  }
  // Longest keys, with values empty, one character, quotes only, marks only.
  m.entries.emplace_back(std::string(24, 'w'), "");
  m.entries.emplace_back(std::string(23, 'v') + "1", "'");
  m.entries.emplace_back(std::string(23, 'v') + "2", "&");
  m.entries.emplace_back(std::string(23, 'v') + "3", std::string(200, '\''));
  m.entries.emplace_back(std::string(23, 'v') + "4", std::string(67, '&'));
  for (int n = 1; n < 80; ++n) m.entries.emplace_back(std::string(20, 'u') + std::to_string(n), std::string(n, 'x'));
  m.units = std::string(150, 'u');
  write_image(make_image(2, 2), path("s.fits"), m, false);
  ImageMetadata back;
  read_image(path("s.fits"), &back);
  expect_same_metadata(m, back);
}

TEST_F(ImageFile, ExrRoundTripIsExact) {
  if (!openimageio_available()) GTEST_SKIP() << "built without OpenImageIO (NEBULA_OPENIMAGEIO=OFF)";
  const Image image = make_image(7, 5);
  const ImageMetadata metadata = make_metadata();
  write_image(image, path("a.exr"), metadata, false);
  ImageMetadata read_metadata;
  // OpenEXR stores channels in its own order; the band order still comes back.
  expect_same_bits(image, read_image(path("a.exr"), &read_metadata));
  expect_same_metadata(metadata, read_metadata);
  EXPECT_EQ(files(), std::vector<std::string>{"a.exr"});
}

#ifdef NEBULA_HAVE_OIIO
struct Png {
  int width = 0, height = 0, channels = 0;
  std::string color_space;
  std::vector<unsigned char> levels;
  int at(int x, int y, int c) const { return levels[(size_t(y) * width + x) * channels + c]; }
};

Png read_png(const std::string& file) {
  auto in = OIIO::ImageInput::open(file);
  if (!in) throw std::runtime_error("test could not open " + file);
  Png png;
  png.width = in->spec().width;
  png.height = in->spec().height;
  png.channels = in->spec().nchannels;
  png.color_space = in->spec().get_string_attribute("oiio:ColorSpace");
  png.levels.resize(size_t(png.width) * png.height * png.channels);
  in->read_image(0, 0, 0, png.channels, OIIO::TypeDesc::UINT8, png.levels.data());
  return png;
}
#endif

// The documented curve, written out again here rather than taken from
// tone_map.h: 12.92 x below 0.0031308, else 1.055 x^(1/2.4) - 0.055.
int expected_level(double linear, double exposure) {
  double x = std::min(std::max(linear * exposure, 0.0), 1.0);
  x = x < 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
  return static_cast<int>(std::floor(255 * x + 0.5));
}

TEST_F(ImageFile, PngIsToneMappedSrgb) {
#ifndef NEBULA_HAVE_OIIO
  GTEST_SKIP() << "built without OpenImageIO (NEBULA_OPENIMAGEIO=OFF)";
#else
  // Bands in a different order from R, G, B: they are placed by name.
  Image image(6, 2, {"V", "R", "B"});
  const float row[6] = {0.0f, 0.0005f, 0.09f, 0.25f, 0.5f, 3.0f};
  for (int x = 0; x < 6; ++x) {
    image.at(0, x, 0) = row[x];          // V: green, top row
    image.at(1, x, 1) = row[x];          // R: red, bottom row
    image.at(2, x, 1) = row[5 - x];      // B: blue, bottom row, reversed
  }
  ImageMetadata m;
  m.exposure = 2.0;
  write_image(image, path("a.png"), m, false);
  const Png png = read_png(path("a.png"));
  ASSERT_EQ(png.width, 6);
  ASSERT_EQ(png.height, 2);
  ASSERT_EQ(png.channels, 3);
  EXPECT_EQ(png.color_space, "sRGB");
  for (int x = 0; x < 6; ++x) {
    EXPECT_EQ(png.at(x, 0, 0), 0);                                      // top row: green only
    EXPECT_NEAR(png.at(x, 0, 1), expected_level(row[x], 2.0), 1) << x;
    EXPECT_EQ(png.at(x, 0, 2), 0);
    EXPECT_NEAR(png.at(x, 1, 0), expected_level(row[x], 2.0), 1) << x;  // bottom: red and blue
    EXPECT_EQ(png.at(x, 1, 1), 0);
    EXPECT_NEAR(png.at(x, 1, 2), expected_level(row[5 - x], 2.0), 1) << x;
  }
  // Known values of the curve: 2 x 0.0005 = 0.001 on the straight part
  // (3.3 levels), 0.18 (18% grey) at 118, 0.5 at 188, clipped above 1.
  EXPECT_NEAR(png.at(1, 0, 1), 3, 1);
  EXPECT_NEAR(png.at(2, 0, 1), 118, 1);
  EXPECT_NEAR(png.at(3, 0, 1), 188, 1);
  EXPECT_EQ(png.at(4, 0, 1), 255);
  EXPECT_EQ(png.at(5, 0, 1), 255);
#endif
}

TEST_F(ImageFile, SingleBandPngIsGrey) {
#ifndef NEBULA_HAVE_OIIO
  GTEST_SKIP() << "built without OpenImageIO (NEBULA_OPENIMAGEIO=OFF)";
#else
  Image image(2, 1, {"V"});
  image.at(0, 0, 0) = 0.18f;
  image.at(0, 1, 0) = 0.0f;
  write_image(image, path("g.png"), ImageMetadata{}, false);
  const Png png = read_png(path("g.png"));
  ASSERT_EQ(png.channels, 1);
  EXPECT_NEAR(png.at(0, 0, 0), 118, 1);
  EXPECT_EQ(png.at(1, 0, 0), 0);
#endif
}

TEST_F(ImageFile, PngNeedsBvrOrOneBand) {
  if (!openimageio_available()) GTEST_SKIP() << "built without OpenImageIO (NEBULA_OPENIMAGEIO=OFF)";
  expect_error([&] { write_image(make_image(2, 2, {"B", "V"}), path("a.png"), {}, false); },
               {"cannot write " + path("a.png"), "B, V, R", "single band", "B,V"});
  expect_error([&] { write_image(make_image(2, 2, {"B", "V", "I"}), path("a.png"), {}, false); },
               {"cannot write " + path("a.png"), "B,V,I"});
  EXPECT_TRUE(files().empty());
}

// Bands other than B, V, R are coloured by their pivot wavelengths
// (pivot_nm_<band>, or pivot_nm_b<plane> for long names): blue to red by rank,
// each channel's weights summing to 1; B, V, R themselves are unchanged.
TEST(PngColours, ByPivotWavelength) {
  const auto near = [](const PngColour& c, float r, float g, float b) {
    EXPECT_NEAR(c.red, r, 1e-6f);
    EXPECT_NEAR(c.green, g, 1e-6f);
    EXPECT_NEAR(c.blue, b, 1e-6f);
  };
  ImageMetadata m;
  const std::vector<PngColour> bvr = png_colours(make_image(1, 1, {"V", "R", "B"}), m);
  near(bvr[0], 0, 1, 0);
  near(bvr[1], 1, 0, 0);
  near(bvr[2], 0, 0, 1);
  near(png_colours(make_image(1, 1, {"F606W"}), m)[0], 1, 1, 1);
  // Three bands in any order: the shortest pivot blue, the middle green, the longest red.
  m.entries = {{"pivot_nm_i", 760.0}, {"pivot_nm_b2", 470.0}, {"pivot_nm_r", 620.0}};
  const std::vector<PngColour> gri = png_colours(make_image(1, 1, {"i", "sdss_g", "r"}), m);
  near(gri[0], 1, 0, 0);
  near(gri[1], 0, 0, 1);
  near(gri[2], 0, 1, 0);
  // Two: blue and red, green their mean.
  m.entries = {{"pivot_nm_x", 500.0}, {"pivot_nm_y", 400.0}};
  const std::vector<PngColour> two = png_colours(make_image(1, 1, {"x", "y"}), m);
  near(two[0], 1, 0.5f, 0);
  near(two[1], 0, 0.5f, 1);
  // Five: hues 240, 180, 120, 60, 0 degrees; every channel sums to 1, so equal planes are grey.
  m.entries = {{"pivot_nm_a", 1.0}, {"pivot_nm_c", 2.0}, {"pivot_nm_d", 3.0}, {"pivot_nm_e", 4.0}, {"pivot_nm_f", 5.0}};
  const std::vector<PngColour> five = png_colours(make_image(1, 1, {"a", "c", "d", "e", "f"}), m);
  float sum[3] = {0, 0, 0};
  for (const PngColour& c : five) {
    sum[0] += c.red;
    sum[1] += c.green;
    sum[2] += c.blue;
  }
  for (float v : sum) EXPECT_NEAR(v, 1.0f, 1e-6f);
  near(five[1], 0, 1.0f / 3, 0.5f);  // cyan: green and blue
  expect_error([&] { png_colours(make_image(1, 1, {"a", "g"}), m); }, {"pivot", "band g"});
}

TEST(ToneMap, CurveAndLevels) {
  EXPECT_DOUBLE_EQ(srgb_encode(0.0), 0.0);
  EXPECT_DOUBLE_EQ(srgb_encode(1.0), 1.0);
  EXPECT_NEAR(srgb_encode(0.0031308), 0.04045, 1e-5);  // the two pieces meet
  EXPECT_NEAR(srgb_encode(0.0031309), 0.04045, 1e-5);
  EXPECT_NEAR(srgb_encode(0.5), 0.735357, 1e-6);
  EXPECT_EQ(srgb_level(0.5f, 1.0), 188);
  EXPECT_EQ(srgb_level(0.25f, 2.0), 188);
  EXPECT_EQ(srgb_level(-1.0f, 1.0), 0);
  EXPECT_EQ(srgb_level(7.0f, 1.0), 255);
  EXPECT_EQ(srgb_level(std::numeric_limits<float>::quiet_NaN(), 1.0), 0);
  for (int i = 0; i <= 1000; ++i) EXPECT_EQ(srgb_level(i / 1000.0f, 1.0), expected_level(i / 1000.0f, 1.0));
}

TEST_F(ImageFile, NoOpenImageIoIsExplained) {
  if (openimageio_available()) GTEST_SKIP() << "built with OpenImageIO";
  for (const char* name : {"a.exr", "a.png"})
    expect_error([&] { write_image(make_image(2, 2), path(name), {}, false); },
                 {"cannot write " + path(name), "needs OpenImageIO", "-DNEBULA_OPENIMAGEIO=ON", ".h5 or .fits"});
  std::ofstream(path("b.exr")) << "x";
  expect_error([&] { read_image(path("b.exr")); }, {path("b.exr"), "OpenImageIO"});
  EXPECT_EQ(files(), std::vector<std::string>{"b.exr"});
}

// ------------------------------------------------------------- refused writes

TEST_F(ImageFile, UnknownExtensionIsRefused) {
  for (const char* name : {"a.tiff", "a", "a.h5.bak"})
    expect_error([&] { write_image(make_image(2, 2), path(name), {}, false); },
                 {"cannot write " + path(name), "unknown image extension", ".h5, .fits, .fit, .exr or .png"});
  expect_error([&] { read_image(path("a.jpg")); }, {path("a.jpg"), "unknown image extension"});
  expect_error([&] { read_image(path("a.png")); }, {path("a.png"), "tone-mapped"});
  EXPECT_TRUE(files().empty());
}

TEST_F(ImageFile, ExistingFileOnlyWhenAsked) {
  for (const char* name : {"a.h5", "a.fits"}) {
    const Image first = make_image(3, 2);
    write_image(first, path(name), {}, false);
    Image second = make_image(3, 2);
    second.at(1, 1, 1) = 42.0f;
    expect_error([&] { write_image(second, path(name), {}, false); },
                 {"cannot write " + path(name), "exists"});
    expect_same_bits(first, read_image(path(name)));  // untouched
    write_image(second, path(name), {}, true);
    expect_same_bits(second, read_image(path(name)));
  }
  EXPECT_EQ(files(), (std::vector<std::string>{"a.fits", "a.h5"}));
}

TEST_F(ImageFile, MissingOrWrongFolderIsRefused) {
  expect_error([&] { write_image(make_image(2, 2), path("no/such/a.h5"), {}, false); },
               {"cannot write " + path("no/such/a.h5"), "folder", "does not exist"});
  std::ofstream(path("plain")) << "a file\n";
  expect_error([&] { write_image(make_image(2, 2), path("plain/a.fits"), {}, false); },
               {"cannot write " + path("plain/a.fits"), "not a folder"});
  fs::create_directory(path("d.h5"));
  expect_error([&] { write_image(make_image(2, 2), path("d.h5"), {}, true); },
               {"cannot write " + path("d.h5"), "folder"});
  EXPECT_EQ(files(), (std::vector<std::string>{"d.h5", "plain"}));
}

TEST_F(ImageFile, ReadOnlyFolderIsRefused) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root, which may write into read-only folders";
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
  expect_error([&] { write_image(make_image(2, 2), path("a.h5"), {}, false); },
               {"cannot write " + path("a.h5") + ": Permission denied"});
  fs::permissions(dir_, fs::perms::owner_all);
  EXPECT_TRUE(files().empty());
}

TEST_F(ImageFile, BadPixelsAreRefusedByName) {
  for (const char* name : {"a.h5", "a.fits", "a.exr", "a.png"}) {
    if (!openimageio_available() && (std::string(name) == "a.exr" || std::string(name) == "a.png")) continue;
    Image image = make_image(4, 3);
    image.at(1, 2, 1) = std::numeric_limits<float>::quiet_NaN();
    expect_error([&] { write_image(image, path(name), {}, false); },
                 {"cannot write " + path(name), "band V", "(x 2, y 1)", "NaN", "no NaN in an output"});
    image.at(1, 2, 1) = std::numeric_limits<float>::infinity();
    expect_error([&] { write_image(image, path(name), {}, false); }, {"band V", "(x 2, y 1)", "+inf"});
    image.at(1, 2, 1) = 0.0f;
    image.at(2, 3, 2) = -0.25f;
    expect_error([&] { write_image(image, path(name), {}, false); },
                 {"band R", "(x 3, y 2)", "negative", "-0.25"});
  }
  EXPECT_TRUE(files().empty());
}

TEST_F(ImageFile, MalformedImagesAreRefused) {
  const std::string file = path("a.h5");
  Image image = make_image(3, 2);
  image.pixels.pop_back();
  expect_error([&] { write_image(image, file, {}, false); }, {"cannot write " + file, "17 values"});
  expect_error([&] { write_image(Image(0, 2, {"V"}), file, {}, false); }, {"0 x 2"});
  expect_error([&] { write_image(Image(2, 2, {}), file, {}, false); }, {"no bands"});
  expect_error([&] { write_image(make_image(2, 2, {"B", "B"}), file, {}, false); }, {"band B appears twice"});
  expect_error([&] { write_image(make_image(2, 2, {"B,V"}), file, {}, false); }, {"band name 'B,V'"});
  expect_error([&] { write_image(make_image(2, 2, {""}), file, {}, false); }, {"band name ''"});
  EXPECT_TRUE(files().empty());
}

TEST_F(ImageFile, BadMetadataIsRefused) {
  const std::string file = path("a.fits");
  auto with = [](MetaEntries entries) {
    ImageMetadata m;
    m.entries = std::move(entries);
    return m;
  };
  const Image image = make_image(2, 2);
  expect_error([&] { write_image(image, file, with({{"has space", "x"}}), false); }, {"'has space'", "[A-Za-z0-9_-]"});
  expect_error([&] { write_image(image, file, with({{"9lives", "x"}}), false); }, {"'9lives'"});
  expect_error([&] { write_image(image, file, with({{std::string(25, 'k'), "x"}}), false); }, {"1 to 24"});
  for (const char* reserved : {"bands", "Units", "exposure", "schema_version", "bscale", "NAXIS2", "band4", "checksum"})
    expect_error([&] { write_image(image, file, with({{reserved, "x"}}), false); },
                 {"metadata key '" + std::string(reserved) + "'", "use themselves"});
  expect_error([&] { write_image(image, file, with({{"g", "1"}, {"G", "2"}}), false); }, {"'G' appears twice"});
  expect_error([&] { write_image(image, file, with({{"note", "tab\there"}}), false); }, {"note", "printable ASCII"});
  expect_error([&] { write_image(image, file, with({{"note", "caf\xc3\xa9"}}), false); }, {"printable ASCII"});
  expect_error([&] { write_image(image, file, with({{"note", "trailing "}}), false); }, {"trailing blanks"});
  ImageMetadata m;
  m.exposure = 0;
  expect_error([&] { write_image(image, file, m, false); }, {"exposure 0", "positive"});
  m.exposure = std::numeric_limits<double>::quiet_NaN();
  expect_error([&] { write_image(image, file, m, false); }, {"exposure", "finite"});
  m = ImageMetadata{};
  m.units = "W\n";
  expect_error([&] { write_image(image, file, m, false); }, {"units 'W\\x0A'"});
  m.units = "";
  expect_error([&] { write_image(image, file, m, false); }, {"units ''", "non-empty"});
  EXPECT_TRUE(files().empty());
}

// Writes under a 16 KiB file-size limit and exits 0 when the write failed
// with a message naming the path and left nothing in `dir`. Runs in the
// death test's child process, which has a test folder of its own.
[[noreturn]] void write_under_size_limit(const std::string& file, const fs::path& dir) {
  ::signal(SIGXFSZ, SIG_IGN);  // make write() fail with EFBIG instead of killing us
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = 16384;
  ::setrlimit(RLIMIT_FSIZE, &limit);
  int code = 0;
  try {
    Image image = make_image(64, 64);  // 48 KiB of floats that no compression shrinks
    std::mt19937 rng(3);
    for (float& v : image.pixels) v = std::uniform_real_distribution<float>(0, 1)(rng);
    write_image(image, file, make_metadata(), false);
    std::cerr << "write succeeded despite the limit\n";
    code = 1;
  } catch (const Error& e) {
    const std::string message = e.what();
    std::cerr << message << "\n";
    if (message.find("cannot write " + file) == std::string::npos) code = 2;
  }
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::cerr << "left behind: " << entry.path() << "\n";
    code = 3;
  }
  // The child made its own fixture (a folder named by its pid) and skips its destructor.
  std::error_code ignored;
  fs::remove_all(dir, ignored);
  // _Exit, not exit: with OpenImageIO loaded, a library's exit handler in
  // the forked child waits for a thread that only the parent has.
  std::cerr.flush();
  std::_Exit(code);
}

// A write that fails half-way (here: the file-size limit, as a full disk
// would) reports the path and leaves neither the target nor the temporary.
TEST_F(ImageFile, FailureMidWriteLeavesNothing) {
  // A forked child would inherit OpenEXR's thread pool without its threads
  // and wait for them forever; "threadsafe" runs the child as a fresh process.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  std::vector<std::string> names = {"big.h5", "big.fits"};
  if (openimageio_available()) names.push_back("big.exr");
  for (const std::string& name : names)
    EXPECT_EXIT(write_under_size_limit(path(name), dir_), ::testing::ExitedWithCode(0), "cannot write")
        << name;
}

TEST_F(ImageFile, ConcurrentWritesAndReads) {
  std::vector<std::thread> threads;
  std::vector<int> failures(8, 0);
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&, t] {
      Image image = make_image(16, 9);
      image.at(2, 5, 5) = float(t);
      for (const char* ext : {".h5", ".fits"}) {
        const std::string file = path(std::string("t") + std::to_string(t) + ext);
        try {
          for (int round = 0; round < 5; ++round) {
            write_image(image, file, make_metadata(), true);
            if (read_image(file).pixels != image.pixels) ++failures[t];
          }
        } catch (const Error&) {
          ++failures[t];
        }
      }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(failures, std::vector<int>(8, 0));
  EXPECT_EQ(files().size(), 16u);
}

// ------------------------------------------------------------- refused reads

TEST_F(ImageFile, MissingGarbageAndFoldersAreRefused) {
  for (const char* name : {"absent.h5", "absent.fits"})
    expect_error([&] { read_image(path(name)); }, {path(name) + ": ", "no such file"});
  fs::create_directory(path("d.fits"));
  expect_error([&] { read_image(path("d.fits")); }, {path("d.fits") + ": ", "folder"});
  for (const char* name : {"text.h5", "text.fits", "empty.h5", "empty.fits"}) {
    std::ofstream out(path(name));
    if (std::string(name).rfind("text", 0) == 0) out << "SIMPLE = not really\n";
  }
  expect_error([&] { read_image(path("text.h5")); }, {path("text.h5") + ": ", "not an HDF5 file"});
  expect_error([&] { read_image(path("empty.h5")); }, {path("empty.h5") + ": ", "not an HDF5 file"});
  expect_error([&] { read_image(path("text.fits")); }, {path("text.fits") + ": ", "cannot open as FITS"});
  expect_error([&] { read_image(path("empty.fits")); }, {path("empty.fits") + ": ", "cannot open as FITS"});
}

// Cut-off copies of a valid file must give an Error at every length.
TEST_F(ImageFile, TruncatedFilesAreRefused) {
  for (const char* name : {"good.h5", "good.fits"}) {
    write_image(make_image(40, 30), path(name), make_metadata(), false);
    const std::string bytes = file_bytes(path(name));
    ASSERT_GT(bytes.size(), 8000u);
    const std::string cut = path(std::string("cut") + fs::path(name).extension().string());
    for (size_t length : {size_t(0), size_t(8), size_t(100), size_t(1000), size_t(2880), size_t(5760),
                          bytes.size() / 2, bytes.size() - 2880, bytes.size() - 1}) {
      std::ofstream(cut, std::ios::binary | std::ios::trunc).write(bytes.data(), length);
      expect_error([&] { read_image(cut); }, {cut + ": "});
    }
  }
}

// Bit flips anywhere: each read either refuses with an Error naming the
// file or returns exactly what was written (the flip hit unused space); it
// never crashes and never returns damaged pixels or metadata. The HDF5
// file's checksummed metadata and chunks and the FITS CHECKSUM and DATASUM
// keywords see to that.
TEST_F(ImageFile, DamagedFilesAreRefusedOrHarmless) {
  const Image image = make_image(20, 10);
  const ImageMetadata metadata = make_metadata();
  for (const char* name : {"good.h5", "good.fits"}) {
    write_image(image, path(name), metadata, false);
    const std::string bytes = file_bytes(path(name));
    const std::string bad = path(std::string("bad") + fs::path(name).extension().string());
    std::mt19937 rng(7);
    int refused = 0;
    const int trials = 300;
    for (int trial = 0; trial < trials; ++trial) {
      std::string damaged = bytes;
      const int flips = 1 + static_cast<int>(rng() % 3);
      for (int f = 0; f < flips; ++f) damaged[rng() % damaged.size()] ^= static_cast<char>(1u << (rng() % 8));
      std::ofstream(bad, std::ios::binary | std::ios::trunc) << damaged;
      try {
        ImageMetadata m;
        const Image read = read_image(bad, &m);
        expect_same_bits(image, read);
        expect_same_metadata(metadata, m);
      } catch (const Error& e) {
        ++refused;
        EXPECT_EQ(std::string(e.what()).rfind(bad + ": ", 0), 0u) << e.what();
      }
    }
    std::cout << name << ": " << refused << " of " << trials << " damaged copies refused, the rest read intact\n";
    EXPECT_GT(refused, trials / 2);
  }
}

// --- HDF5 files edited after writing

class RefusedHdf5 : public ImageFile {
 protected:
  template <class Edit>
  void expect_refused(Edit edit, const std::vector<std::string>& pieces) {
    const std::string file = path("e.h5");
    write_image(make_image(4, 3), file, make_metadata(), true);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    edit(f);
    H5Fclose(f);
    std::vector<std::string> all{file + ": "};
    all.insert(all.end(), pieces.begin(), pieces.end());
    expect_error([&] { read_image(file); }, all);
  }
  static void set_dataset(hid_t f, hid_t type, std::vector<hsize_t> dims, const void* data) {
    H5Ldelete(f, "/image", H5P_DEFAULT);
    const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    const hid_t set = H5Dcreate2(f, "/image", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(set);
    H5Sclose(space);
  }
  static void set_attribute(hid_t f, const char* name, hid_t type, const void* value) {
    if (H5Aexists(f, name) > 0) H5Adelete(f, name);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(f, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, type, value);
    H5Aclose(attr);
    H5Sclose(space);
  }
  static void set_string(hid_t f, const char* name, const std::string& value) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    const char* text = value.c_str();
    set_attribute(f, name, type, &text);
    H5Tclose(type);
  }
};

TEST_F(RefusedHdf5, MissingImage) {
  expect_refused([](hid_t f) { H5Ldelete(f, "/image", H5P_DEFAULT); }, {"/image", "no such dataset"});
}

TEST_F(RefusedHdf5, ImageOfIntegers) {
  const std::vector<int> data(36, 1);
  expect_refused([&](hid_t f) { set_dataset(f, H5T_NATIVE_INT, {3, 3, 4}, data.data()); },
                 {"/image", "class integer"});
}

TEST_F(RefusedHdf5, ImageOfRankTwo) {
  const std::vector<float> data(12, 1.0f);
  expect_refused([&](hid_t f) { set_dataset(f, H5T_NATIVE_FLOAT, {3, 4}, data.data()); }, {"/image", "rank 2"});
}

TEST_F(RefusedHdf5, BandsNotMatchingTheImage) {
  expect_refused([](hid_t f) { set_string(f, "bands", "B,V"); }, {"bands", "3 comma-separated", "'B,V'"});
}

TEST_F(RefusedHdf5, RepeatedBand) {
  expect_refused([](hid_t f) { set_string(f, "bands", "B,V,V"); }, {"bands", "distinct"});
}

TEST_F(RefusedHdf5, MissingUnits) {
  expect_refused([](hid_t f) { H5Adelete(f, "units"); }, {"units", "no such attribute"});
}

TEST_F(RefusedHdf5, WrongSchemaVersion) {
  const int three = 3;
  expect_refused([&](hid_t f) { set_attribute(f, "schema_version", H5T_NATIVE_INT, &three); },
                 {"schema_version", "found 3"});
}

TEST_F(RefusedHdf5, ExposureAsAString) {
  expect_refused([](hid_t f) { set_string(f, "exposure", "1"); }, {"exposure", "class string"});
}

TEST_F(RefusedHdf5, EntryThatIsNotANumberOrString) {
  const unsigned char x = 6;
  expect_refused(
      [&](hid_t f) {
        H5Adelete(f, "albedo_V");
        const hid_t type = H5Tcreate(H5T_OPAQUE, 1);
        H5Tset_tag(type, "bytes");
        set_attribute(f, "albedo_V", type, &x);
        H5Tclose(type);
      },
      {"albedo_V", "integer, float or string attribute", "class other"});
}

TEST_F(RefusedHdf5, NaNPixel) {
  expect_refused(
      [](hid_t f) {
        std::vector<float> data(36, 1.0f);
        data[12 + 4 + 1] = std::numeric_limits<float>::quiet_NaN();
        const hid_t set = H5Dopen2(f, "/image", H5P_DEFAULT);
        H5Dwrite(set, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data());
        H5Dclose(set);
      },
      {"pixels", "non-finite", "band V", "(x 1, y 1)"});
}

TEST_F(ImageFile, Hdf5VariableLengthStringsAreRead) {
  const std::string file = path("v.h5");
  write_image(make_image(2, 2), file, ImageMetadata{}, false);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(f, "observer", type, space, H5P_DEFAULT, H5P_DEFAULT);
  const char* text = "someone else's tool";
  H5Awrite(attr, type, &text);
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
  H5Fclose(f);
  ImageMetadata m;
  read_image(file, &m);
  EXPECT_TRUE(m.entries == (MetaEntries{{"observer", "someone else's tool"}}));
}

// --- FITS files edited after writing

class RefusedFits : public ImageFile {
 protected:
  // A valid file edited by `edit`; the checksums are removed first (unless
  // `keep_checksums`) so that the edit itself is what the reader meets.
  template <class Edit>
  void expect_refused(Edit edit, const std::vector<std::string>& pieces, bool keep_checksums = false) {
    const std::string file = path("e.fits");
    write_image(make_image(4, 3), file, make_metadata(), true);
    fitsfile* f = nullptr;
    int status = 0;
    ASSERT_EQ(fits_open_diskfile(&f, file.c_str(), READWRITE, &status), 0);
    if (!keep_checksums) {
      fits_delete_key(f, "CHECKSUM", &status);
      fits_delete_key(f, "DATASUM", &status);
    }
    edit(f, status);
    EXPECT_EQ(status, 0) << "the edit itself failed";
    fits_close_file(f, &status);
    std::vector<std::string> all{file + ": "};
    all.insert(all.end(), pieces.begin(), pieces.end());
    expect_error([&] { read_image(file); }, all);
  }
};

TEST_F(RefusedFits, DamagedDataFailsItsChecksum) {
  const std::string file = path("e.fits");
  ImageMetadata m = make_metadata();
  m.scene_text.clear();  // no SCENE extension: the file ends with the pixels
  write_image(make_image(4, 3), file, m, true);
  std::string bytes = file_bytes(file);
  bytes[bytes.size() - 2880 + 5] ^= 0x10;  // inside the pixels
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  expect_error([&] { read_image(file); }, {file + ": ", "DATASUM", "mismatch"});
}

TEST_F(RefusedFits, EditedHeaderFailsItsChecksum) {
  expect_refused([](fitsfile* f, int& status) { fits_update_key_str(f, "BAND2", "I", nullptr, &status); },
                 {"CHECKSUM", "mismatch"}, true);
}

TEST_F(RefusedFits, MissingBand) {
  expect_refused([](fitsfile* f, int& status) { fits_delete_key(f, "BAND2", &status); },
                 {"BAND2", "naming band 2", "no such keyword"});
}

TEST_F(RefusedFits, UnitsNotAString) {
  expect_refused(
      [](fitsfile* f, int& status) {
        fits_delete_key(f, "BUNIT", &status);
        int one = 1;
        fits_write_key(f, TINT, "BUNIT", &one, nullptr, &status);
      },
      {"BUNIT", "not a string"});
}

TEST_F(RefusedFits, MissingExposure) {
  expect_refused([](fitsfile* f, int& status) { fits_delete_key(f, "EXPOSURE", &status); },
                 {"EXPOSURE", "no such keyword"});
}

TEST_F(RefusedFits, NegativeExposure) {
  expect_refused([](fitsfile* f, int& status) { fits_update_key_dbl(f, "EXPOSURE", -1.0, 6, nullptr, &status); },
                 {"EXPOSURE", "positive"});
}

TEST_F(RefusedFits, EntryWhoseCommentNamesAnotherKey) {
  expect_refused([](fitsfile* f, int& status) { fits_modify_comment(f, "G", "nebula key: h", &status); },
                 {"G", "matching the keyword", "nebula key: h"});
}

TEST_F(RefusedFits, NaNPixel) {
  expect_refused(
      [](fitsfile* f, int& status) {
        float nan = std::numeric_limits<float>::quiet_NaN();
        long pixel[3] = {2, 1, 3};  // FITS row 1 is the bottom row: y = 2 of 3
        fits_write_pix(f, TFLOAT, pixel, 1, &nan, &status);
      },
      {"pixels", "non-finite", "band R", "(x 1, y 2)"});
}

TEST_F(ImageFile, FitsOfTheWrongShapeIsRefused) {
  const std::string file = path("flat.fits");
  fitsfile* f = nullptr;
  int status = 0;
  fits_create_diskfile(&f, const_cast<char*>(file.c_str()), &status);
  long axes[2] = {4, 3};
  fits_create_img(f, FLOAT_IMG, 2, axes, &status);
  std::vector<float> data(12, 1.0f);
  fits_write_img(f, TFLOAT, 1, 12, data.data(), &status);
  fits_close_file(f, &status);
  ASSERT_EQ(status, 0);
  expect_error([&] { read_image(file); }, {file + ": ", "NAXIS", "expected 3", "found 2"});
}

// Keywords other tools add are kept out of the entries; only those marked
// by the writer come back.
TEST_F(ImageFile, ForeignFitsKeywordsAreNotEntries) {
  const std::string file = path("f.fits");
  ImageMetadata m;
  m.entries = {{"albedo_B", "0.6"}};
  write_image(make_image(3, 2), file, m, false);
  fitsfile* f = nullptr;
  int status = 0;
  fits_open_diskfile(&f, file.c_str(), READWRITE, &status);
  fits_write_key_str(f, "OBJECT", "NGC 1977", "target", &status);
  fits_write_history(f, "processed elsewhere", &status);
  fits_write_chksum(f, &status);
  fits_close_file(f, &status);
  ASSERT_EQ(status, 0);
  ImageMetadata back;
  read_image(file, &back);
  expect_same_metadata(m, back);
}

TEST(ImagePaths, VarianceLivesBesideTheImage) {
  EXPECT_EQ(variance_path("out/truth.h5"), "out/truth.var.h5");
  EXPECT_EQ(variance_path("a.b/truth"), "a.b/truth.var");
}

}  // namespace
}  // namespace nebula
