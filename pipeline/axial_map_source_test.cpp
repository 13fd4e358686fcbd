// Axial maps built from a scene's [axial] table: synthetic, an HDF5 2D
// dataset (with emission datasets), and an image with named channels.
#include <gtest/gtest.h>

#include "pipeline/axial_map_source.h"

#include <memory>

#include "pipeline/render_scene.h"
#include "core/error.h"
#include "imageio/image_output.h"
#include "scene/scene_file.h"
#include "scene/test_files.h"

namespace nebula {
namespace {

class AxialMapSource : public testing::TempDirTest {
 protected:
  Scene scene(const std::string& axial_lines) {
    const std::string text = "bands = [\"B\", \"V\"]\n[axial]\n" + axial_lines +
                             "\nlength_pc = 2.0\n[camera]\nposition = [4.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\n";
    return load_scene(write_text("axial.toml", text));
  }
};

TEST_F(AxialMapSource, Synthetic) {
  const AxialMap m = build_axial_map(scene("synthetic = \"shells\"\nnx = 40\nnr = 20\ntau_scale = 2.0"));
  const AxialMap ref = synthetic_axial_map("shells", 40, 20, 1.0f, 2);
  EXPECT_EQ(m.nx, 40);
  EXPECT_FLOAT_EQ(m.texel, 0.05f);
  ASSERT_EQ(m.emission.size(), 2u);
  for (size_t i = 0; i < m.count(); ++i) ASSERT_FLOAT_EQ(m.tau_v[i], 2.0f * ref.tau_v[i]);
  EXPECT_EQ(m.global_max, ref.global_max);
}

// A map given in memory (the viewer's painted one) renders in the scene's
// place of its own: the scene's map given so renders the same image bit for
// bit; emptied, nothing shines (no stars: emission is the only light).
TEST_F(AxialMapSource, MapInMemoryReplacesTheScenes) {
  Scene s = scene("synthetic = \"shells\"\nnx = 40\nnr = 20\ntau_scale = 2.0\norigin = [0.0, 0.0, 0.5]");
  s.camera.width = 24;
  s.camera.height = 24;
  const AxialMap built = build_axial_map(s);
  AxialMap unplaced = built;
  unplaced.texel = 7;
  unplaced.origin = {9, 9, 9};
  const AxialMap placed = place_axial_map(s, unplaced);
  EXPECT_FLOAT_EQ(placed.texel, 0.05f);
  EXPECT_FLOAT_EQ(placed.origin.z, 0.5f);
  EXPECT_EQ(placed.tau_v, built.tau_v);  // no tau_scale applied a second time

  RenderOptions o;
  const RenderOutput plain = render_scene(s, o);
  o.axial_map = std::make_shared<const AxialMap>(built);
  const RenderOutput given = render_scene(s, o);
  double total = 0;
  for (float v : plain.image.pixels) total += v;
  ASSERT_GT(total, 0);
  EXPECT_EQ(given.image.pixels, plain.image.pixels);
  EXPECT_EQ(given.report.axial->source, "in memory (painted)");

  AxialMap dark = built;
  for (auto& plane : dark.emission) std::fill(plane.begin(), plane.end(), 0.0f);
  o.axial_map = std::make_shared<const AxialMap>(dark);
  for (float v : render_scene(s, o).image.pixels) ASSERT_EQ(v, 0.0f);

  AxialMap three = built;
  three.emission.push_back(three.emission[0]);
  o.axial_map = std::make_shared<const AxialMap>(three);
  testing::expect_error([&] { render_scene(s, o); }, {"axial", "3 emission planes", "2 bands"});
}

TEST_F(AxialMapSource, Hdf5DatasetsWithEmission) {
  testing::H5Dataset tau, glow_b, glow_v;
  tau.dims = glow_b.dims = glow_v.dims = {3, 5};  // [nr][nx]
  for (int i = 0; i < 15; ++i) {
    tau.values.push_back(i % 5 == 4 ? 0.0 : 0.1 * i);
    glow_b.values.push_back(0.5);
    glow_v.values.push_back(0.25);
  }
  glow_b.name = "glow_B";
  glow_v.name = "glow_V";
  testing::write_h5(path("map.h5"), {tau, glow_b, glow_v});
  const AxialMap m = build_axial_map(scene("file = \"map.h5\"\nemission_prefix = \"glow_\"\nemission_scale = 2.0"));
  EXPECT_EQ(m.nx, 5);
  EXPECT_EQ(m.nr, 3);
  EXPECT_FLOAT_EQ(m.texel, 0.4f);
  EXPECT_FLOAT_EQ(m.tau_v[m.index(2, 1)], 0.7f);  // value 7: [r = 1][x = 2]
  ASSERT_EQ(m.emission.size(), 2u);
  EXPECT_FLOAT_EQ(m.emission[0][3], 1.0f);
  EXPECT_FLOAT_EQ(m.emission[1][3], 0.5f);
  glow_v.dims = {3, 4};
  glow_v.values.resize(12);
  testing::write_h5(path("bad.h5"), {tau, glow_b, glow_v});
  testing::expect_error([&] { build_axial_map(scene("file = \"bad.h5\"\nemission_prefix = \"glow_\"")); },
                        {"axial.file", "glow_V", "3 x 4"});
}

TEST_F(AxialMapSource, ImageChannelsWithTheAxisAtTheBottom) {
  Image image(4, 3, {"dust", "blue"});
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) {
      image.at(0, x, y) = float(10 * y + x);  // row 0 (top) = the outermost texels
      image.at(1, x, y) = 1.0f;
    }
  write_image(image, path("map.h5"), ImageMetadata{}, false);
  const AxialMap m = build_axial_map(
      scene("image = \"map.h5\"\ntau_channel = \"dust\"\nemission_channels = { B = \"blue\" }"));
  EXPECT_EQ(m.nx, 4);
  EXPECT_EQ(m.nr, 3);
  EXPECT_FLOAT_EQ(m.tau_v[m.index(1, 0)], 21.0f);  // the bottom row is the axis
  EXPECT_FLOAT_EQ(m.tau_v[m.index(1, 2)], 1.0f);
  ASSERT_EQ(m.emission.size(), 2u);
  EXPECT_FLOAT_EQ(m.emission[0][0], 1.0f);
  EXPECT_FLOAT_EQ(m.emission[1][0], 0.0f);  // V has no channel
  testing::expect_error([&] { build_axial_map(scene("image = \"map.h5\"")); },
                        {"axial.tau_channel", "'tau_v'", "dust, blue"});
}

// Any OpenImageIO format: a PNG (8-bit sRGB, channels R, G, B) read as floats in [0, 1].
TEST_F(AxialMapSource, AnyOpenImageIoFormat) {
  if (!openimageio_available()) GTEST_SKIP() << "this build has no OpenImageIO";
  Image image(6, 4, {"B", "V", "R"});
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) image.at(1, x, y) = x == 0 ? 0.0f : 0.5f;
  write_image(image, path("map.png"), ImageMetadata{}, false);
  const AxialMap m = build_axial_map(scene("image = \"map.png\"\ntau_channel = \"G\""));
  EXPECT_EQ(m.nx, 6);
  EXPECT_EQ(m.nr, 4);
  EXPECT_EQ(m.tau_v[m.index(0, 2)], 0.0f);
  EXPECT_GT(m.tau_v[m.index(3, 2)], 0.0f);
  EXPECT_LE(m.tau_v[m.index(3, 2)], 1.0f);
  EXPECT_EQ(m.height[0], 0);
  EXPECT_EQ(m.height[3], 4);
  testing::expect_error([&] { build_axial_map(scene("image = \"map.png\"\ntau_channel = \"V\"")); },
                        {"axial.tau_channel", "'V'", "R, G, B"});
}

}  // namespace
}  // namespace nebula
