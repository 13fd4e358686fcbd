#include "scene/scene_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "illumination/star.h"
#include "scene/density_sources.h"
#include "scene/test_files.h"

namespace nebula {
namespace {

using testing::expect_error;
using testing::H5Dataset;
using testing::write_fits;
using testing::write_h5;

// A small valid scene; the refusal tests edit it one line at a time.
const char* kBase = R"(
[density]
procedural = { n = 16, size_pc = 2.0, seed = 3 }

[dust]
albedo = 0.6
g = 0.6
R_V = 5.0

[[stars]]
name = "HD 1"
position = [1.0, 1.0, 1.0]
luminosity_lsun = 2e5
class = "O5V"

[camera]
position = [1.0, -3.0, 1.0]
look_at = [1.0, 1.0, 1.0]

[output]
file = "out.exr"
)";

// kBase with the first occurrence of `from` replaced by `to` (which must exist).
std::string edited(const std::string& from, const std::string& to) {
  std::string text = kBase;
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

class SceneFile : public testing::TempDirTest {
 protected:
  // Writes the text as <name>.toml and expects load_scene to refuse it with a
  // message naming the file and every piece.
  void refused(const std::string& name, const std::string& text, std::vector<std::string> pieces,
               const std::vector<std::string>& overrides = {}) {
    const std::string file = write_text(name + ".toml", text);
    pieces.insert(pieces.begin(), name + ".toml");
    SCOPED_TRACE(name);
    expect_error([&] { load_scene(file, overrides); }, pieces);
  }

  // A 4 x 3 x 2 HDF5 density with voxel 0.5 pc; `bad` replaces voxel (1, 2, 1).
  void density_file(const std::string& name, std::optional<double> bad = std::nullopt) {
    H5Dataset set;
    set.dims = {2, 3, 4};
    set.values.assign(24, 0.25);
    if (bad) set.values[21] = *bad;
    set.voxel_size = 0.5;
    write_h5(path(name), {set});
  }
};

TEST_F(SceneFile, BaseSceneLoadsWithDefaults) {
  const Scene s = load_scene(write_text("base.toml", kBase));
  EXPECT_EQ(s.path, path("base.toml"));
  EXPECT_EQ(s.bands, (std::vector<std::string>{"B", "V", "R"}));
  EXPECT_EQ(s.density.shape.nx, 16);
  EXPECT_FLOAT_EQ(s.density.shape.voxel, 0.125f);
  EXPECT_TRUE(s.emission.empty());
  EXPECT_EQ(s.dust.albedo, std::vector<double>(3, 0.6));
  EXPECT_EQ(s.dust.g, std::vector<double>(3, 0.6));
  EXPECT_EQ(s.dust.R_V, 5.0);
  EXPECT_EQ(s.dust.law, ExtinctionLaw::CCM89);
  EXPECT_EQ(s.dust.table_files, std::vector<std::string>(3, ""));
  ASSERT_EQ(s.stars.size(), 1u);
  EXPECT_EQ(s.stars[0].name, "HD 1");
  EXPECT_EQ(s.stars[0].temperature_K, 41400.0);
  EXPECT_EQ(s.stars[0].spectral_class, "O5V");
  EXPECT_EQ(s.stars[0].luminosity_lsun, 2e5);
  EXPECT_EQ(s.camera.projection, Projection::Perspective);
  EXPECT_EQ(s.camera.up.z, 1.0f);
  EXPECT_EQ(s.camera.fov_deg, 40.0);
  EXPECT_EQ(s.camera.width, 512);
  EXPECT_EQ(s.camera.height, 512);
  EXPECT_EQ(s.camera.exposure, 1.0);
  EXPECT_EQ(s.output, "out.exr");
  EXPECT_FALSE(s.draw_stars);
  EXPECT_EQ(s.star_psf_pixels, 1.5);
  EXPECT_NO_THROW(validate_scene(s));
}

TEST_F(SceneFile, EveryFeatureLoads) {
  density_file("data/cloud.h5");
  H5Dataset b, v, r;
  b.name = "glow_B";
  v.name = "glow_V";
  r.name = "glow_R";
  for (H5Dataset* e : {&b, &v, &r}) {
    e->dims = {2, 3, 4};
    e->values.assign(24, 0.0);
  }
  b.values[5] = 2.5;
  write_h5(path("data/glow.h5"), {b, v, r});
  write_text("tables/tB.h5", "placeholder");  // only its existence is checked here
  const std::string text = R"(
bands = ["B", "V", "R"]
[density]
file = "data/cloud.h5"
dataset = "tau_v"
scale = 2.0
[emission]
file = "data/glow.h5"
prefix = "glow_"
[dust]
albedo = { B = 0.7, V = 0.6, R = 0.5 }
g = { R = 0.5, V = 0.55, B = 0.65 }
R_V = 3.1
law = "odonnell94"
tables = { B = "tables/tB.h5", V = "" }
[[stars]]
position = [0.5, 0.5, 0.5]
luminosity_lsun = 1e3
temperature_K = 9000
[[stars]]
name = "second"
position = [1.5, 1.0, 0.5]
luminosity_lsun = 50
class = "g2v"
temperature_K = 5770
[camera]
kind = "orthographic"
position = [1, 0.75, 10]
look_at = [1, 0.75, 0.5]
up = [0, 1, 0]
ortho_width = 2.5
width = 640
height = 480
exposure = 3.0
[output]
file = "nebula.fits"
draw_stars = true
star_psf_pixels = 2.0
)";
  const Scene s = load_scene(write_text("full.toml", text));
  EXPECT_EQ(s.density.shape.nx, 4);
  EXPECT_EQ(s.density.shape.nz, 2);
  EXPECT_EQ(s.density.tau_v[0], 0.5f);  // 0.25 x scale 2
  EXPECT_EQ(s.density_scale, 2.0);
  ASSERT_EQ(s.emission.size(), 3u);
  EXPECT_EQ(s.emission[0][5], 2.5f);
  // emission.scale multiplies every band's emission (and only the emission).
  std::string scaled = text;
  scaled.replace(scaled.find("prefix = \"glow_\""), 16, "prefix = \"glow_\"\nscale = 0.25");
  const Scene q = load_scene(write_text("scaled.toml", scaled));
  ASSERT_EQ(q.emission.size(), 3u);
  EXPECT_EQ(q.emission[0][5], 0.625f);
  EXPECT_EQ(q.emission[0][4], 0.0f);
  EXPECT_EQ(q.density.tau_v, s.density.tau_v);
  EXPECT_EQ(q.emission_scale, 0.25);
  EXPECT_EQ(s.emission_scale, 1.0);
  EXPECT_EQ(s.dust.albedo, (std::vector<double>{0.7, 0.6, 0.5}));
  EXPECT_EQ(s.dust.g, (std::vector<double>{0.65, 0.55, 0.5}));
  EXPECT_EQ(s.dust.R_V, 3.1);
  EXPECT_EQ(s.dust.law, ExtinctionLaw::ODonnell94);
  EXPECT_EQ(s.dust.table_files[0], path("tables/tB.h5"));
  EXPECT_EQ(s.dust.table_files[1], "");
  EXPECT_EQ(s.dust.table_files[2], "");
  ASSERT_EQ(s.stars.size(), 2u);
  EXPECT_EQ(s.stars[0].name, "star 0");
  EXPECT_EQ(s.stars[0].temperature_K, 9000.0);
  EXPECT_EQ(s.stars[0].spectral_class, "");
  EXPECT_EQ(s.stars[1].temperature_K, 5770.0);
  EXPECT_FLOAT_EQ(s.stars[1].position.x, 1.5f);
  EXPECT_EQ(s.camera.projection, Projection::Orthographic);
  EXPECT_EQ(s.camera.ortho_width, 2.5);
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);
  EXPECT_EQ(s.camera.exposure, 3.0);
  EXPECT_EQ(s.output, "nebula.fits");
  EXPECT_TRUE(s.draw_stars);
  EXPECT_EQ(s.star_psf_pixels, 2.0);

  // One band only: per-band vectors follow the scene's bands.
  const Scene v_only = load_scene_text(
      std::string("bands = [\"V\"]\n") + kBase, "v.toml", dir_.string(), {"dust.albedo={V=0.4}"});
  EXPECT_EQ(v_only.dust.albedo, std::vector<double>{0.4});
  EXPECT_EQ(v_only.dust.g, std::vector<double>{0.6});
}

TEST_F(SceneFile, FitsDensityWithTheScenesVoxelSize) {
  write_fits(path("cube.fits"), {4, 3, 2}, std::vector<double>(24, 0.5), FLOAT_IMG, {});
  const Scene s = load_scene(write_text(
      "fits.toml", edited("procedural = { n = 16, size_pc = 2.0, seed = 3 }",
                          "fits = \"cube.fits\"\nvoxel_size_pc = 0.25")));
  EXPECT_EQ(s.density.shape.nx, 4);
  EXPECT_FLOAT_EQ(s.density.shape.voxel, 0.25f);
}

TEST_F(SceneFile, StarsMayTakeTheProceduralStarsPosition) {
  const Scene s = load_scene(write_text("p.toml", edited("position = [1.0, 1.0, 1.0]\n", "")),
                             {"density.procedural.star=[0.25, 0.5, 0.75]"});
  EXPECT_FLOAT_EQ(s.stars[0].position.x, 0.5f);
  EXPECT_FLOAT_EQ(s.stars[0].position.y, 1.0f);
  EXPECT_FLOAT_EQ(s.stars[0].position.z, 1.5f);
}

// ------------------------------------------------------------ refusals

const char* kProcedural = "procedural = { n = 16, size_pc = 2.0, seed = 3 }";

TEST_F(SceneFile, RefusesUnknownKeysAtEveryLevel) {
  refused("top", std::string("colour = 1\n") + kBase, {"colour", "unknown key"});
  refused("camera_key", edited("[camera]\n", "[camera]\nfvo_deg = 30\n"), {"camera.fvo_deg", "unknown key", "fov_deg"});
  refused("procedural_key", edited("seed = 3", "seed = 3, bubble_radiu = 0.1"),
          {"density.procedural.bubble_radiu", "unknown key"});
  refused("star_key", edited("class = \"O5V\"", "class = \"O5V\"\nlum = 3"), {"stars.0.lum", "unknown key"});
  refused("density_key", edited("[density]\n", "[density]\nformat = \"h5\"\n"), {"density.format", "unknown key"});
  refused("dust_key", edited("R_V = 5.0", "R_V = 5.0\nRv = 3"), {"dust.Rv", "unknown key"});
  refused("output_key", edited("file = \"out.exr\"", "files = \"out.exr\""), {"output.files", "unknown key"});
  refused("band_key", edited("albedo = 0.6", "albedo = { B = 0.6, V = 0.6, R = 0.6, U = 0.5 }"),
          {"dust.albedo.U", "unknown band"});
  refused("tables_key", edited("R_V = 5.0", "R_V = 5.0\ntables = { I = \"t.h5\" }"), {"dust.tables.I", "unknown band"});
  refused("emission_key", std::string("[emission]\nfile = \"e.h5\"\ngain = 2\n") + kBase, {"emission.gain", "unknown key"});
  refused("emission_scale", std::string("[emission]\nfile = \"e.h5\"\nscale = -1\n") + kBase, {"emission.scale", ">= 0"});
}

TEST_F(SceneFile, RefusesWrongTypes) {
  refused("fov_string", edited("[camera]\n", "[camera]\nfov_deg = \"wide\"\n"), {"camera.fov_deg", "number", "string"});
  refused("width_float", edited("[camera]\n", "[camera]\nwidth = 512.5\n"), {"camera.width", "integer", "float"});
  refused("position_short", edited("position = [1.0, -3.0, 1.0]", "position = [1.0, -3.0]"),
          {"camera.position", "3 numbers"});
  refused("position_text", edited("position = [1.0, -3.0, 1.0]", "position = [1.0, \"a\", 1.0]"),
          {"camera.position[1]", "number"});
  refused("stars_table", edited("[[stars]]", "[stars]"), {"stars", "array of tables"});
  refused("draw_stars", edited("file = \"out.exr\"", "draw_stars = 1"), {"output.draw_stars", "true or false"});
  refused("camera_value",
          "camera = 3\n" + edited("[camera]\nposition = [1.0, -3.0, 1.0]\nlook_at = [1.0, 1.0, 1.0]", ""),
          {"camera", "must be a table, got an integer"});
  refused("seed_float", edited("seed = 3", "seed = 3.5"), {"density.procedural.seed", "integer"});
  refused("nan", edited("R_V = 5.0", "R_V = nan"), {"dust.R_V", "finite"});
  refused("syntax", edited("R_V = 5.0", "R_V = = 5"), {"TOML syntax"});
}

TEST_F(SceneFile, RefusesMissingRequiredKeys) {
  std::string no_density = kBase;
  no_density.replace(no_density.find("[density]"), std::string("[density]\n").size() + std::strlen(kProcedural) + 1, "");
  refused("no_density", no_density, {"density", "missing"});
  refused("no_source", edited(kProcedural, ""), {"density", "one of file"});
  refused("no_camera", edited("[camera]\nposition = [1.0, -3.0, 1.0]\nlook_at = [1.0, 1.0, 1.0]", ""),
          {"camera", "missing"});
  refused("no_look_at", edited("look_at = [1.0, 1.0, 1.0]", ""), {"camera.look_at", "missing"});
  refused("no_luminosity", edited("luminosity_lsun = 2e5", ""), {"stars.0.luminosity_lsun", "missing"});
  refused("no_colour", edited("class = \"O5V\"", ""), {"stars.0", "temperature_K or class"});
  std::string no_stars = kBase;
  no_stars.replace(no_stars.find("[[stars]]"), no_stars.find("[camera]") - no_stars.find("[[stars]]"), "");
  refused("no_stars", no_stars, {"stars", "at least one"});
  density_file("cloud.h5");
  std::string file_density = edited(kProcedural, "file = \"cloud.h5\"");
  const std::string star_position = "position = [1.0, 1.0, 1.0]\n";
  file_density.erase(file_density.find(star_position), star_position.size());
  refused("no_star_position", file_density, {"stars.0.position", "missing"});
  refused("ortho_no_width", edited("[camera]\n", "[camera]\nkind = \"orthographic\"\n"), {"camera.ortho_width", "missing"});
  refused("emission_no_file", std::string("[emission]\nprefix = \"e_\"\n") + kBase, {"emission.file", "missing"});
}

TEST_F(SceneFile, RefusesBadDensityFiles) {
  refused("missing_file", edited(kProcedural, "file = \"nowhere/cloud.h5\""),
          {"density.file", "nowhere/cloud.h5", "cannot open"});
  write_text("notes.h5", "just text");
  refused("not_hdf5", edited(kProcedural, "file = \"notes.h5\""), {"density.file", "notes.h5", "not an HDF5"});
  density_file("nan.h5", std::nan(""));
  refused("nan_density", edited(kProcedural, "file = \"nan.h5\""), {"density.file", "nan.h5", "index 21", "nan"});
  density_file("negative.h5", -2.0);
  refused("negative_density", edited(kProcedural, "file = \"negative.h5\""), {"density.file", "index 21", "-2"});
  density_file("inf.h5", INFINITY);
  refused("inf_density", edited(kProcedural, "file = \"inf.h5\""), {"density.file", "index 21", "inf"});
  density_file("cloud.h5");
  refused("dataset", edited(kProcedural, "file = \"cloud.h5\"\ndataset = \"rho\""), {"density.file", "'rho'", "not found"});
  refused("two_sources", edited(kProcedural, std::string(kProcedural) + "\nfile = \"cloud.h5\""),
          {"density.procedural", "conflicts with density.file"});
  refused("voxel_with_h5", edited(kProcedural, "file = \"cloud.h5\"\nvoxel_size_pc = 0.1"),
          {"density.voxel_size_pc", "fits only"});
  write_fits(path("cube.fits"), {4, 3, 2}, std::vector<double>(24, 0.5), FLOAT_IMG, {});
  refused("fits_no_voxel", edited(kProcedural, "fits = \"cube.fits\""), {"density.fits", "cube.fits", "CDELT"});
  refused("scale", edited(kProcedural, std::string(kProcedural) + "\nscale = 0"), {"density.scale", "> 0"});
  refused("scale_overflow", edited(kProcedural, "file = \"cloud.h5\"\nscale = 1e300"), {"density.scale", "inf"});

  H5Dataset huge;
  huge.dims = {100000, 100000, 100000};
  huge.voxel_size = 0.1;
  write_h5(path("huge.h5"), {huge});
  refused("huge", edited(kProcedural, "file = \"huge.h5\""), {"density.file", "huge.h5", "3.55 PiB", "limit"});
  refused("huge_procedural", edited("n = 16", "n = 100000"), {"density.procedural.n", "limit"});
  refused("procedural_param", edited("seed = 3", "seed = 3, bubble_offset = 0.5"),
          {"density.procedural.bubble_offset", "bubble_radius"});

  H5Dataset e;
  e.name = "emission_B";
  e.dims = {2, 3, 5};
  e.values.assign(30, 0.0);
  write_h5(path("em.h5"), {e});
  refused("emission_shape", std::string("[emission]\nfile = \"em.h5\"\n") + edited(kProcedural, "file = \"cloud.h5\""),
          {"emission.file", "em.h5", "emission_B", "differs"});
  refused("table_missing", edited("R_V = 5.0", "R_V = 5.0\ntables = { V = \"tV.h5\" }"), {"dust.tables.V", "tV.h5"});
}

// The viewer's painted map saved: the [axial] table reads the file instead of
// building its map, with the scales of 1 (the file holds the values as
// rendered); everything else, deformations included, as written.
TEST_F(SceneFile, AxialMapFileReplacesTheKeysNamingTheMap) {
  const std::string text = R"(bands = ["B", "V"]
[axial]
synthetic = "bipolar"
nx = 64
nr = 32
tau_scale = 3.0
emission_scale = 0.5
length_pc = 4.0
step_texels = 0.25
[axial.colour_deform]
kind = "simplex"
[camera]
position = [4.0, 0.0, 1.0]
look_at = [0.0, 0.0, 1.0]
)";
  write_text("painted.map.h5", "only its existence is checked here");
  const std::string out = scene_text_with_axial_file(text, "painted.map.h5", "emission_");
  const Scene s = load_scene(write_text("painted.toml", out));
  ASSERT_TRUE(s.axial.has_value());
  EXPECT_EQ(s.axial->source, "file");
  EXPECT_EQ(s.axial->path, path("painted.map.h5"));
  EXPECT_EQ(s.axial->dataset, "tau_v");
  EXPECT_EQ(s.axial->emission_prefix, "emission_");
  EXPECT_EQ(s.axial->tau_scale, 1.0);
  EXPECT_EQ(s.axial->emission_scale, 1.0);
  EXPECT_EQ(s.axial->length_pc, 4.0);
  EXPECT_EQ(s.axial->step_texels, 0.25);
  EXPECT_TRUE(s.axial->colour_deform.on);
  EXPECT_EQ(s.axial->colour_deform.kind, "simplex");
  EXPECT_EQ(scene_text_with_axial_file(text, "m.h5", "").find("emission_prefix"), std::string::npos);
  testing::expect_error([&] { scene_text_with_axial_file("[camera]\nfov_deg = 30\n", "m.h5", ""); },
                        {"no [axial] table", "m.h5"});
}

// Two scenes that differ only in the keys left out give equal texts; any
// other difference stays (what a spectral preparation with other filters reuses).
TEST_F(SceneFile, TextWithoutSomeKeysComparesTheRest) {
  const std::string a = "bands = [\"B\", \"V\"]\n[spectral]\nmethod = \"projection\"\nrange_um = [0.3, 1.0]\n"
                        "[camera]\nfov_deg = 30\n";
  const std::string b = "bands = [\"sdss_g\"]\n[spectral]\nmethod = \"projection\"\n[camera]\nfov_deg = 50\n";
  const std::vector<std::string> keys = {"bands", "camera", "spectral.range_um", "output.file", "no.such.key"};
  EXPECT_EQ(scene_text_without(a, keys), scene_text_without(b, keys));
  EXPECT_NE(scene_text_without(a, {"bands", "camera"}), scene_text_without(b, {"bands", "camera"}));
  const std::string c = "bands = [\"B\"]\n[spectral]\nmethod = \"double\"\n";
  EXPECT_NE(scene_text_without(a, keys), scene_text_without(c, keys));
  EXPECT_EQ(scene_text_without(a, keys).find("range_um"), std::string::npos);
  EXPECT_NE(scene_text_without(a, keys).find("method"), std::string::npos);
  testing::expect_error([&] { scene_text_without("bands = [", keys); }, {"scene text", "TOML syntax"});
}

TEST_F(SceneFile, RefusesAMissingSceneFile) {
  expect_error([&] { load_scene(path("nothing.toml")); }, {"nothing.toml", "cannot read", "No such file"});
  expect_error([&] { load_scene(dir_.string()); }, {"directory"});
}

TEST_F(SceneFile, RefusesBadStars) {
  refused("zero_luminosity", edited("2e5", "0"), {"stars.0.luminosity_lsun", "> 0"});
  refused("negative_luminosity", edited("2e5", "-1"), {"stars.0.luminosity_lsun", "> 0"});
  refused("unknown_class", edited("\"O5V\"", "\"X9V\""), {"stars.0.class", "X9V", "O5V"});
  refused("disagreeing", edited("class = \"O5V\"", "class = \"O5V\"\ntemperature_K = 30000"),
          {"stars.0.temperature_K", "30000", "41400", "O5V"});
  refused("cold", edited("class = \"O5V\"", "temperature_K = -5"), {"stars.0.temperature_K", "> 0"});
  // The second star is named by its index.
  refused("second", std::string(kBase) + "[[stars]]\nposition = [0, 0, 0]\nluminosity_lsun = 1\n",
          {"stars.1", "temperature_K or class"});
}

TEST_F(SceneFile, RefusesBadDust) {
  refused("albedo_high", edited("albedo = 0.6", "albedo = 1.2"), {"dust.albedo", "[0, 1]"});
  refused("albedo_band", edited("albedo = 0.6", "albedo = { B = -0.1, V = 0.6, R = 0.6 }"), {"dust.albedo.B", "[0, 1]"});
  refused("albedo_missing_band", edited("albedo = 0.6", "albedo = { B = 0.5, V = 0.6 }"), {"dust.albedo.R", "every band"});
  refused("g_one", edited("g = 0.6", "g = 1.0"), {"dust.g", "(-1, 1)"});
  refused("g_minus_one", edited("g = 0.6", "g = -1"), {"dust.g", "(-1, 1)"});
  refused("rv_low", edited("R_V = 5.0", "R_V = 1.5"), {"dust.R_V", "[2, 6]"});
  refused("rv_high", edited("R_V = 5.0", "R_V = 6.5"), {"dust.R_V", "[2, 6]"});
  refused("law", edited("R_V = 5.0", "law = \"fitzpatrick99\""), {"dust.law", "fitzpatrick99"});
  refused("bands", std::string("bands = [\"B\", \"X\"]\n") + kBase, {"bands", "'X'"});
  refused("bands_twice", std::string("bands = [\"B\", \"B\"]\n") + kBase, {"bands", "twice"});
}

// render.diffuse_zonal: "auto" (the default: 24 when a band's g >= 0.8), a
// whole number above diffuse_order up to 32, or 0; anything else refused by name.
TEST_F(SceneFile, DiffuseZonalIsAutoOrAWholeNumberAboveTheOrder) {
  const Scene base = load_scene(write_text("zonal_base.toml", kBase));
  EXPECT_EQ(base.diffuse.zonal, DiffuseSettings::kZonalAuto);
  EXPECT_EQ(resolved_zonal(base.diffuse, base.dust.g), 0) << "g = 0.6 in every band";
  EXPECT_EQ(resolved_zonal(base.diffuse, {0.6, 0.85, 0.6}), 24) << "one band of strongly forward dust";
  const Scene fixed = load_scene(write_text("zonal_12.toml", kBase + std::string("\n[render]\ndiffuse_zonal = 12\n")));
  EXPECT_EQ(resolved_zonal(fixed.diffuse, {0.9}), 12);
  const Scene none = load_scene(write_text("zonal_0.toml", kBase + std::string("\n[render]\ndiffuse_zonal = 0\n")));
  EXPECT_EQ(resolved_zonal(none.diffuse, {0.9}), 0);
  const Scene spelled = load_scene(write_text("zonal_auto.toml", kBase + std::string("\n[render]\ndiffuse_zonal = \"AUTO\"\n")));
  EXPECT_EQ(spelled.diffuse.zonal, DiffuseSettings::kZonalAuto);
  refused("zonal_word", kBase + std::string("\n[render]\ndiffuse_zonal = \"many\"\n"), {"render.diffuse_zonal", "auto"});
  refused("zonal_low", kBase + std::string("\n[render]\ndiffuse_zonal = 3\n"), {"render.diffuse_zonal", "above render.diffuse_order"});
  refused("zonal_high", kBase + std::string("\n[render]\ndiffuse_zonal = 40\n"), {"render.diffuse_zonal", "at most 32"});
  refused("zonal_minus_one", kBase + std::string("\n[render]\ndiffuse_zonal = -1\n"), {"render.diffuse_zonal", "\"auto\""});
}

// render.diffuse_taper: "auto" (the default), "none" or "lanczos", any case;
// anything else refused by name.
TEST_F(SceneFile, DiffuseTaperIsAutoNoneOrLanczos) {
  EXPECT_EQ(load_scene(write_text("taper_base.toml", kBase)).diffuse.taper, DiffuseTaper::Auto);
  EXPECT_EQ(load_scene(write_text("taper_l.toml", kBase + std::string("\n[render]\ndiffuse_taper = \"Lanczos\"\n")))
                .diffuse.taper,
            DiffuseTaper::Lanczos);
  EXPECT_EQ(load_scene(write_text("taper_n.toml", kBase + std::string("\n[render]\ndiffuse_taper = \"NONE\"\n")))
                .diffuse.taper,
            DiffuseTaper::None);
  EXPECT_EQ(load_scene(write_text("taper_a.toml", kBase + std::string("\n[render]\ndiffuse_taper = \"auto\"\n")))
                .diffuse.taper,
            DiffuseTaper::Auto);
  refused("taper_word", kBase + std::string("\n[render]\ndiffuse_taper = \"zonal\"\n"),
          {"render.diffuse_taper", "auto, none, lanczos"});
  refused("taper_number", kBase + std::string("\n[render]\ndiffuse_taper = 1\n"), {"render.diffuse_taper"});
}

// render.star_pixels: true by default (the pixels at a star's image marched
// with many rays each), false turns it off; anything but a boolean refused.
TEST_F(SceneFile, StarPixelsAreOnUnlessTurnedOff) {
  EXPECT_TRUE(load_scene(write_text("star_pixels_base.toml", kBase)).star_pixels);
  EXPECT_FALSE(load_scene(write_text("star_pixels_off.toml", kBase + std::string("\n[render]\nstar_pixels = false\n")))
                   .star_pixels);
  refused("star_pixels_word", kBase + std::string("\n[render]\nstar_pixels = \"yes\"\n"),
          {"render.star_pixels", "true or false"});
}

// render.diffuse_order: "auto" (the default: 4, or 3 where zonal degrees carry
// the stars' light), or a whole number 0 to 4; anything else refused by name.
TEST_F(SceneFile, DiffuseOrderIsAutoOrAWholeNumberUpToFour) {
  const Scene base = load_scene(write_text("order_base.toml", kBase));
  EXPECT_EQ(base.diffuse.order, DiffuseSettings::kOrderAuto);
  EXPECT_EQ(resolved_order(base.diffuse, base.dust.g), 4) << "g = 0.6 in every band: no zonal degrees";
  EXPECT_EQ(resolved_order(base.diffuse, {0.6, 0.85, 0.6}), 3) << "zonal degrees for strongly forward dust";
  const Scene no_zonal = load_scene(write_text("order_nozonal.toml", kBase + std::string("\n[render]\ndiffuse_zonal = 0\n")));
  EXPECT_EQ(resolved_order(no_zonal.diffuse, {0.9}), 4);
  const Scene fixed = load_scene(write_text("order_2.toml", kBase + std::string("\n[render]\ndiffuse_order = 2\n")));
  EXPECT_EQ(resolved_order(fixed.diffuse, {0.6}), 2);
  EXPECT_EQ(resolved_order(fixed.diffuse, {0.9}), 2);
  const Scene spelled = load_scene(write_text("order_auto.toml", kBase + std::string("\n[render]\ndiffuse_order = \"Auto\"\n")));
  EXPECT_EQ(spelled.diffuse.order, DiffuseSettings::kOrderAuto);
  refused("order_word", kBase + std::string("\n[render]\ndiffuse_order = \"high\"\n"), {"render.diffuse_order", "auto"});
  refused("order_high", kBase + std::string("\n[render]\ndiffuse_order = 5\n"), {"render.diffuse_order", "0..4"});
  refused("order_negative", kBase + std::string("\n[render]\ndiffuse_order = -2\n"), {"render.diffuse_order", "0..4"});
  refused("order_minus_one", kBase + std::string("\n[render]\ndiffuse_order = -1\n"), {"render.diffuse_order", "0..4"});
}

TEST_F(SceneFile, RefusesBadCameras) {
  refused("zero_view", edited("look_at = [1.0, 1.0, 1.0]", "look_at = [1.0, -3.0, 1.0]"), {"camera.look_at", "zero length"});
  refused("up_parallel", edited("[camera]\n", "[camera]\nup = [0, 2, 0]\n"), {"camera.up", "parallel"});
  refused("up_zero", edited("[camera]\n", "[camera]\nup = [0, 0, 0]\n"), {"camera.up", "zero"});
  refused("fov_zero", edited("[camera]\n", "[camera]\nfov_deg = 0\n"), {"camera.fov_deg", "(0, 180)"});
  refused("fov_180", edited("[camera]\n", "[camera]\nfov_deg = 180\n"), {"camera.fov_deg", "(0, 180)"});
  refused("width_zero", edited("[camera]\n", "[camera]\nwidth = 0\n"), {"camera.width", ">= 1"});
  refused("height_negative", edited("[camera]\n", "[camera]\nheight = -4\n"), {"camera.height", ">= 1"});
  refused("fisheye_wide", edited("[camera]\n", "[camera]\nkind = \"fisheye\"\nwidth = 1024\n"), {"camera.height", "square"});
  refused("kind", edited("[camera]\n", "[camera]\nkind = \"pinhole\"\n"), {"camera.kind", "pinhole"});
  refused("exposure", edited("[camera]\n", "[camera]\nexposure = 0\n"), {"camera.exposure", "> 0"});
  refused("ortho_negative", edited("[camera]\n", "[camera]\nkind = \"orthographic\"\northo_width = -2\n"),
          {"camera.ortho_width", "> 0"});
  refused("psf", edited("file = \"out.exr\"", "star_psf_pixels = 0"), {"output.star_psf_pixels"});
}

// ------------------------------------------------------------ overrides

TEST_F(SceneFile, OverridesApplyBeforeValidation) {
  const std::string file = write_text("o.toml", kBase);
  const Scene s = load_scene(file, {"camera.fov_deg=30", "dust.albedo=0.8", "stars.0.luminosity_lsun=1e4",
                                    "camera.kind=fisheye", "output.draw_stars=true",
                                    "dust.g={B=0.7, V=0.6, R=0.5}", "camera.position=[1, -4, 1]",
                                    "stars.0.name=\"renamed\"", "camera.look_at.2=1.5"});
  EXPECT_EQ(s.camera.fov_deg, 30.0);
  EXPECT_EQ(s.dust.albedo, std::vector<double>(3, 0.8));
  EXPECT_EQ(s.stars[0].luminosity_lsun, 1e4);
  EXPECT_EQ(s.stars[0].name, "renamed");
  EXPECT_EQ(s.camera.projection, Projection::Fisheye);
  EXPECT_TRUE(s.draw_stars);
  EXPECT_EQ(s.dust.g, (std::vector<double>{0.7, 0.6, 0.5}));
  EXPECT_FLOAT_EQ(s.camera.position.y, -4.0f);
  EXPECT_FLOAT_EQ(s.camera.look_at.z, 1.5f);  // one element of an array

  // An override can repair a file (validation comes after), create a table,
  // append a star and change the procedural seed.
  const Scene t = load_scene(write_text("fix.toml", edited("R_V = 5.0", "R_V = 9")),
                             {"dust.R_V=3.1", "stars.1.luminosity_lsun=10", "stars.1.class=B0V",
                              "stars.1.position=[0, 0, 0]", "density.procedural.seed=4"});
  EXPECT_EQ(t.dust.R_V, 3.1);
  ASSERT_EQ(t.stars.size(), 2u);
  EXPECT_EQ(t.stars[1].temperature_K, 31400.0);
  EXPECT_NE(t.density.tau_v, s.density.tau_v);

  std::string no_output = kBase;
  no_output.erase(no_output.find("[output]"));
  const Scene u = load_scene(write_text("noout.toml", no_output), {"output.file=x.fits"});
  EXPECT_EQ(u.output, "x.fits");
}

TEST_F(SceneFile, OverridesAreCheckedLikeTheFile) {
  write_text("o.toml", kBase);
  refused("o", kBase, {"camera.fvo_deg", "unknown key", "set by override 'camera.fvo_deg=30'"}, {"camera.fvo_deg=30"});
  refused("o", kBase, {"colour", "unknown key", "override"}, {"colour.red=1"});
  refused("o", kBase, {"camera.fov_deg", "(0, 180)", "set by override 'camera.fov_deg=200'"}, {"camera.fov_deg=200"});
  refused("o", kBase, {"camera.width", "integer", "string", "override"}, {"camera.width=wide"});
  refused("o", kBase, {"dust.albedo", "[0, 1]", "override"}, {"dust.albedo=2"});
  refused("o", kBase, {"stars.5", "out of range", "1 elements"}, {"stars.5.luminosity_lsun=3"});
  refused("o", kBase, {"stars.x", "0-based index"}, {"stars.x.luminosity_lsun=3"});
  refused("o", kBase, {"dust.R_V", "is a float, not a table"}, {"dust.R_V.x=1"});
  refused("o", kBase, {"camera.position.x", "0-based index"}, {"camera.position.x=1"});
  refused("o", kBase, {"override 'fov'", "KEY=VALUE"}, {"fov"});
  refused("o", kBase, {"override", "bad key"}, {"camera..fov_deg=3"});
}

// ------------------------------------------------------------ built-in and examples

const std::string kScenes = NEBULA_SCENES_DIR;

void expect_same_scene(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.bands, b.bands);
  EXPECT_EQ(a.density.shape.nx, b.density.shape.nx);
  EXPECT_EQ(a.density.shape.ny, b.density.shape.ny);
  EXPECT_EQ(a.density.shape.nz, b.density.shape.nz);
  EXPECT_EQ(a.density.shape.voxel, b.density.shape.voxel);
  EXPECT_EQ(a.density.shape.origin.x, b.density.shape.origin.x);
  EXPECT_EQ(a.density.shape.origin.y, b.density.shape.origin.y);
  EXPECT_EQ(a.density.shape.origin.z, b.density.shape.origin.z);
  EXPECT_TRUE(a.density.tau_v == b.density.tau_v);
  EXPECT_EQ(a.emission.size(), b.emission.size());
  EXPECT_EQ(a.dust.albedo, b.dust.albedo);
  EXPECT_EQ(a.dust.g, b.dust.g);
  EXPECT_EQ(a.dust.R_V, b.dust.R_V);
  EXPECT_EQ(a.dust.law, b.dust.law);
  EXPECT_EQ(a.dust.table_files, b.dust.table_files);
  ASSERT_EQ(a.stars.size(), b.stars.size());
  for (size_t i = 0; i < a.stars.size(); ++i) {
    EXPECT_EQ(a.stars[i].name, b.stars[i].name);
    EXPECT_EQ(a.stars[i].position.x, b.stars[i].position.x);
    EXPECT_EQ(a.stars[i].position.y, b.stars[i].position.y);
    EXPECT_EQ(a.stars[i].position.z, b.stars[i].position.z);
    EXPECT_EQ(a.stars[i].luminosity_lsun, b.stars[i].luminosity_lsun);
    EXPECT_EQ(a.stars[i].temperature_K, b.stars[i].temperature_K);
    EXPECT_EQ(a.stars[i].spectral_class, b.stars[i].spectral_class);
  }
  const CameraSettings &c = a.camera, &d = b.camera;
  EXPECT_EQ(c.projection, d.projection);
  for (auto [p, q] : {std::pair{c.position, d.position}, {c.look_at, d.look_at}, {c.up, d.up}}) {
    EXPECT_EQ(p.x, q.x);
    EXPECT_EQ(p.y, q.y);
    EXPECT_EQ(p.z, q.z);
  }
  EXPECT_EQ(c.fov_deg, d.fov_deg);
  EXPECT_EQ(c.ortho_width, d.ortho_width);
  EXPECT_EQ(c.width, d.width);
  EXPECT_EQ(c.height, d.height);
  EXPECT_EQ(c.exposure, d.exposure);
  EXPECT_TRUE(a.display == b.display);
  ASSERT_EQ(a.camera_path.has_value(), b.camera_path.has_value());
  if (a.camera_path) {
    EXPECT_EQ(a.camera_path->timing, b.camera_path->timing);
    ASSERT_EQ(a.camera_path->keys.size(), b.camera_path->keys.size());
    for (size_t i = 0; i < a.camera_path->keys.size(); ++i) {
      const CameraKeyframe &k = a.camera_path->keys[i], &l = b.camera_path->keys[i];
      EXPECT_EQ(k.time, l.time);
      EXPECT_EQ(k.fov_deg, l.fov_deg);
      for (auto [p, q] : {std::pair{k.position, l.position}, {k.look_at, l.look_at}, {k.up, l.up}}) {
        EXPECT_EQ(p.x, q.x);
        EXPECT_EQ(p.y, q.y);
        EXPECT_EQ(p.z, q.z);
      }
    }
  }
  EXPECT_EQ(a.output, b.output);
  EXPECT_EQ(a.draw_stars, b.draw_stars);
  EXPECT_EQ(a.star_psf_pixels, b.star_psf_pixels);
}

TEST(Examples, DemoSceneValidatesAndEqualsDemoToml) {
  const Scene demo = demo_scene();
  EXPECT_NO_THROW(validate_scene(demo));
  EXPECT_EQ(demo.density.shape.nx, 128);
  ASSERT_EQ(demo.stars.size(), 1u);
  EXPECT_EQ(demo.stars[0].spectral_class, "O5V");
  // The camera is outside the cloud, looking at the star.
  const Vec3 upper = demo.density.shape.upper();
  EXPECT_TRUE(demo.camera.position.y < demo.density.shape.origin.y || demo.camera.position.y > upper.y);
  const Scene file = load_scene(kScenes + "/demo.toml");
  expect_same_scene(file, demo);
}

TEST(Examples, Fig12ReferenceLoads) {
  const Scene s = load_scene(kScenes + "/fig12_reference.toml");
  EXPECT_EQ(s.dust.albedo, std::vector<double>(3, 0.6));
  EXPECT_EQ(s.dust.g, std::vector<double>(3, 0.6));
  EXPECT_EQ(s.dust.R_V, 5.0);
  ASSERT_EQ(s.stars.size(), 1u);
  EXPECT_EQ(s.stars[0].spectral_class, "O5V");
  // The paper's variations are one override away.
  const Scene g2 = load_scene(kScenes + "/fig12_reference.toml",
                              {"stars.0.class=G2V", "dust.R_V=3.1"});
  EXPECT_EQ(g2.stars[0].temperature_K, 5770.0);
  EXPECT_EQ(g2.dust.R_V, 3.1);
}

TEST(Examples, UniformSphereIsUniformInsideAndEmptyOutside) {
  const Scene s = load_scene(kScenes + "/uniform_sphere.toml");
  const GridShape& g = s.density.shape;
  const Vec3 star = s.stars.at(0).position;
  const double radius = 0.4 * g.nx * g.voxel;  // bubble_radius 0.4 of the edge
  float inside = -1;
  size_t in = 0, out = 0;
  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x) {
        const Vec3 c = g.centre(x, y, z);
        const double r = length(c - star);
        const float v = s.density.tau_v[g.index(x, y, z)];
        if (r < radius - 0.5 * g.voxel) {
          if (inside < 0) inside = v;
          ASSERT_EQ(v, inside);
          ++in;
        } else if (r > radius + 0.5 * g.voxel) {
          ASSERT_EQ(v, 0.0f);
          ++out;
        }
      }
  EXPECT_GT(inside, 0.0f);
  EXPECT_GT(in, 1000u);
  EXPECT_GT(out, 1000u);
}

TEST(Examples, EveryExampleSceneLoads) {
  size_t count = 0;
  for (const auto& entry : testing::fs::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(load_scene(entry.path().string()));
    ++count;
  }
  EXPECT_GE(count, 3u);
}

TEST(Scene, ValidateSceneNamesTheKey) {
  Scene s = demo_scene();
  s.camera.fov_deg = 0;
  expect_error([&] { validate_scene(s); }, {"demo", "camera.fov_deg"});
  s = demo_scene();
  s.dust.albedo = {0.6, 1.5, 0.6};
  expect_error([&] { validate_scene(s); }, {"demo", "dust.albedo.V"});
  s = demo_scene();
  s.density.tau_v[7] = -1;
  expect_error([&] { validate_scene(s); }, {"demo", "density", "index 7"});
  s = demo_scene();
  s.stars[0].temperature_K = 5000;
  expect_error([&] { validate_scene(s); }, {"demo", "stars.0.temperature_K", "O5V"});
  s = demo_scene();
  s.dust.g.pop_back();
  expect_error([&] { validate_scene(s); }, {"demo", "dust.g", "2 values for 3 bands"});
  EXPECT_STREQ(to_string(Projection::Fisheye), "fisheye");
}

}  // namespace
}  // namespace nebula

namespace nebula {
namespace {

TEST_F(SceneFile, RenderLevelsIsReadAndChecked) {
  const Scene none = load_scene(write_text("plain.toml", kBase));
  EXPECT_EQ(none.pyramid_levels, 0);
  const Scene three = load_scene(write_text("levels.toml", std::string(kBase) + "[render]\nlevels = 3\n"));
  EXPECT_EQ(three.pyramid_levels, 3);
  const Scene set = load_scene(write_text("set.toml", kBase), {"render.levels=2"});
  EXPECT_EQ(set.pyramid_levels, 2);
  refused("negative", std::string(kBase) + "[render]\nlevels = -1\n", {"render.levels", "0..16"});
  refused("float", std::string(kBase) + "[render]\nlevels = 1.5\n", {"render.levels", "integer"});
  refused("unknown", std::string(kBase) + "[render]\nstep = 1\n", {"render.step"});
}

// [filters]: a user curve a band may name; [spectral]: the spectral renderer's
// settings, each bad value refused naming its key.
TEST_F(SceneFile, UserFiltersAndTheSpectralTableAreReadAndChecked) {
  write_text("filters/ha.txt", "# H-alpha, 3 nm\n650 0\n655, 0.9\n656.3\t1.0\n660 0\n");
  const std::string with_filter =
      std::string("bands = [\"V\", \"Halpha\", \"sdss_g\"]\n[filters]\nHalpha = \"filters/ha.txt\"\n") + kBase;
  const Scene plain = load_scene(write_text("filter.toml", with_filter));
  ASSERT_EQ(plain.filters.size(), 1u);
  EXPECT_EQ(plain.filters[0].name, "Halpha");
  EXPECT_EQ(plain.filters[0].passband.wavelength_nm.size(), 4u);
  EXPECT_EQ(plain.bands[1], "Halpha");
  EXPECT_FALSE(plain.spectral);
  bool listed = false;
  for (const SceneInput& in : plain.inputs) listed = listed || in.key == "filters.Halpha";
  EXPECT_TRUE(listed);

  const Scene spectral = load_scene(write_text("spectral.toml", with_filter + "[spectral]\nmethod = \"Double\"\n"
                                                                              "wavelengths = 64\nfit_depth = 6\n"));
  ASSERT_TRUE(spectral.spectral);
  EXPECT_EQ(spectral.spectral->method, "double");
  EXPECT_EQ(spectral.spectral->wavelengths, 64);
  EXPECT_EQ(spectral.spectral->basis, 4);
  EXPECT_EQ(spectral.spectral->fit_depth, 6.0);
  EXPECT_EQ(spectral.spectral->attenuation, "law");
  EXPECT_TRUE(spectral.spectral->tables);
  EXPECT_EQ(spectral.spectral->table_nodes, 3);
  const Scene thin =
      load_scene(write_text("thin.toml", with_filter + "[spectral]\ntables = false\ntable_nodes = 2\n"));
  EXPECT_FALSE(thin.spectral->tables);
  EXPECT_EQ(thin.spectral->table_nodes, 2);

  write_text("filters/bad.txt", "650 0\n660 1\n655 1\n");
  refused("bad_curve", std::string("bands = [\"Hx\"]\n[filters]\nHx = \"filters/bad.txt\"\n") + kBase,
          {"filters.Hx", "bad.txt:3", "strictly ascending"});
  refused("missing_curve", std::string("[filters]\nHy = \"filters/none.txt\"\n") + kBase, {"filters.Hy", "cannot open"});
  write_text("filters/v.txt", "500 0\n550 1\n600 0\n");
  refused("builtin_name", std::string("[filters]\nV = \"filters/v.txt\"\n") + kBase, {"filters.V", "built-in"});
  refused("plane_name", std::string("[filters]\nb2 = \"filters/v.txt\"\n") + kBase, {"filters.b2", "plane"});
  refused("unknown_band", std::string("bands = [\"Hz\"]\n") + kBase, {"bands", "'Hz'"});
  const std::string s = std::string(kBase) + "[spectral]\n";
  refused("basis_zero", s + "basis = 0\n", {"spectral.basis", "1..16"});
  refused("basis_big", s + "basis = 17\n", {"spectral.basis", "1..16"});
  refused("method", s + "method = \"fast\"\n", {"spectral.method", "'fast'"});
  refused("analytic_law", s + "method = \"analytic\"\n", {"spectral.method", "inverse"});
  refused("samples", s + "method = \"double\"\nwavelengths = 1\n", {"spectral.wavelengths", "2..4096"});
  refused("attenuation", s + "attenuation = \"fitz\"\n", {"spectral.attenuation", "'fitz'"});
  refused("norm", s + "norm = \"max\"\n", {"spectral.norm", "'max'"});
  refused("fit_depth", s + "fit_depth = -1\n", {"spectral.fit_depth", "[0, 1000]"});
  refused("fit_past_max", s + "fit_depth = 9\nmax_depth = 5\n", {"spectral.fit_depth", "max_depth"});
  refused("range", s + "range_um = [0.9, 0.3]\n", {"spectral.range_um", "0 < lo < hi"});
  refused("near_voxels", s + "near_voxels = -1\n", {"spectral.near_voxels", "[0, 1000]"});
  refused("table_nodes", s + "table_nodes = 0\n", {"spectral.table_nodes", "1..4"});
  refused("tables", s + "tables = \"yes\"\n", {"spectral.tables", "true or false"});
  refused("voxel_method", s + "method = \"voxels\"\n", {"spectral.method", "voxel_light"});
  refused("key", s + "elements = 3\n", {"spectral.elements", "unknown key"});
  refused("temperature", edited("class = \"O5V\"", "temperature_K = 0") + "[spectral]\n",
          {"stars.0.temperature_K", "> 0"});
  refused("light_range", edited("class = \"O5V\"", "temperature_K = 90000") + "[spectral]\nmethod = \"light_density\"\n",
          {"stars.0.temperature_K", "2000 to 60000"});
  refused("albedo_per_band", edited("albedo = 0.6", "albedo = { B = 0.5, V = 0.6, R = 0.6 }") + "[spectral]\n",
          {"dust.albedo", "one albedo"});
  refused("override", kBase, {"spectral.basis", "1..16", "override 'spectral.basis=0'"}, {"spectral.basis=0"});
}

// [[spectral.emission]]: lines and continua, weighted by the voxel's tau_V or
// by a grid from an HDF5 file (scale applied at load); each bad value refused
// naming its component's key.
TEST_F(SceneFile, SpectralEmissionComponentsAreReadAndChecked) {
  H5Dataset ha;
  ha.name = "ha";
  ha.dims = {16, 16, 16};
  ha.values.assign(4096, 0.0);
  ha.values[7] = 2.0;
  write_h5(path("glow.h5"), {ha});
  const std::string s = std::string(kBase) + "[spectral]\n";
  const Scene scene = load_scene(write_text("glow.toml", s + "[[spectral.emission]]\nline_nm = 656.28\nfile = \"glow.h5\"\n"
                                                             "dataset = \"ha\"\nscale = 0.5\n"
                                                             "[[spectral.emission]]\ncontinuum = [0.1, 0.2]\n"
                                                             "range_nm = [500, 700]\n"));
  ASSERT_EQ(scene.spectral->emission.size(), 2u);
  EXPECT_EQ(scene.spectral->emission[0].line_nm, 656.28);
  EXPECT_EQ(scene.spectral->emission[1].continuum, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(scene.spectral->emission[1].hi_nm, 700.0);
  ASSERT_EQ(scene.spectral->emission_grids.size(), 2u);
  EXPECT_EQ(scene.spectral->emission_grids[0][7], 1.0f);  // 2 x scale 0.5
  EXPECT_TRUE(scene.spectral->emission_grids[1].empty());  // tau_V weights
  bool listed = false;
  for (const SceneInput& in : scene.inputs) listed = listed || in.key == "spectral.emission.0.file";
  EXPECT_TRUE(listed);
  // Emission alone lights a spectral scene: no star needed.
  std::string starless = s;
  starless.erase(starless.find("[[stars]]"), starless.find("[camera]") - starless.find("[[stars]]"));
  EXPECT_NO_THROW(load_scene(write_text("starless.toml", starless + "[[spectral.emission]]\nline_nm = 500\n")));

  refused("both", s + "[[spectral.emission]]\nline_nm = 500\ncontinuum = [1]\n", {"spectral.emission.0", "exactly one"});
  refused("neither", s + "[[spectral.emission]]\nscale = 2\n", {"spectral.emission.0", "exactly one"});
  refused("line", s + "[[spectral.emission]]\nline_nm = -5\n", {"spectral.emission.0.line_nm", "> 0"});
  refused("empty", s + "[[spectral.emission]]\ncontinuum = []\n", {"spectral.emission.0.continuum", "1 to 8"});
  refused("range", s + "[[spectral.emission]]\ncontinuum = [1]\nrange_nm = [700, 500]\n",
          {"spectral.emission.0.range_nm", "0 < lo < hi"});
  refused("line_range", s + "[[spectral.emission]]\nline_nm = 500\nrange_nm = [400, 600]\n",
          {"spectral.emission.0.range_nm", "a line"});
  refused("scale", s + "[[spectral.emission]]\nline_nm = 500\nscale = -1\n", {"spectral.emission.0.scale", ">= 0"});
  refused("dataset", s + "[[spectral.emission]]\nline_nm = 500\nfile = \"glow.h5\"\n",
          {"spectral.emission.0", "file and dataset"});
  refused("missing", s + "[[spectral.emission]]\nline_nm = 500\nfile = \"no.h5\"\ndataset = \"ha\"\n",
          {"spectral.emission.0.file", "no.h5"});
  refused("key", s + "[[spectral.emission]]\nline_nm = 500\nwidth_nm = 1\n", {"spectral.emission.0.width_nm", "unknown key"});
  refused("table", s + "emission = 3\n", {"spectral.emission", "array of tables"});
  write_text("e.h5", "placeholder");
  refused("band_emission", std::string("[emission]\nfile = \"e.h5\"\n") + s, {"emission", "[[spectral.emission]]"});
}

const char* kAxial = R"(
[axial]
synthetic = "shells"
nx = 64
nr = 32
length_pc = 2.0
origin = [0.0, 0.0, -1.0]
axis = [0.0, 0.0, 2.0]

[[stars]]
position = [0.0, 0.0, 0.5]
luminosity_lsun = 100
class = "B5V"

[camera]
position = [4.0, 0.0, 0.0]
look_at = [0.0, 0.0, 0.0]
)";

std::string axial_edited(const std::string& from, const std::string& to) {
  std::string text = kAxial;
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

class AxialSceneFile : public testing::TempDirTest {
 protected:
  void refused(const std::string& name, const std::string& text, std::vector<std::string> pieces,
               const std::vector<std::string>& overrides = {}) {
    const std::string file = write_text(name + ".toml", text);
    pieces.insert(pieces.begin(), name + ".toml");
    SCOPED_TRACE(name);
    testing::expect_error([&] { load_scene(file, overrides); }, pieces);
  }
};

TEST_F(AxialSceneFile, LoadsWithDefaultsAndANormalisedAxis) {
  const Scene s = load_scene(write_text("axial.toml", kAxial));
  ASSERT_TRUE(s.axial.has_value());
  EXPECT_EQ(s.axial->source, "synthetic");
  EXPECT_EQ(s.axial->synthetic, "shells");
  EXPECT_EQ(s.axial->nx, 64);
  EXPECT_EQ(s.axial->nr, 32);
  EXPECT_FLOAT_EQ(s.axial->axis.z, 1.0f);
  EXPECT_EQ(s.axial->skip, "distance");
  EXPECT_EQ(s.axial->step_texels, 0.5);
  EXPECT_EQ(s.density.tau_v.size(), 0u);
  EXPECT_NO_THROW(validate_scene(s));
  const Scene naive = load_scene(path("axial.toml"), {"axial.skip=naive"});
  EXPECT_EQ(naive.axial->skip, "naive");
}

TEST_F(AxialSceneFile, HdfMapFileIsResolvedAndChecked) {
  testing::H5Dataset set;
  set.name = "tau_v";
  set.dims = {4, 8};  // [nr][nx]
  set.values.assign(32, 0.1);
  testing::write_h5(path("maps/m.h5"), {set});
  const Scene s = load_scene(write_text("f.toml", axial_edited("synthetic = \"shells\"\nnx = 64\nnr = 32",
                                                               "file = \"maps/m.h5\"")));
  EXPECT_EQ(s.axial->source, "file");
  int nx = 0, nr = 0;
  const std::vector<float> tau = load_axial_plane_hdf5(s.axial->path, "tau_v", nx, nr);
  EXPECT_EQ(nx, 8);
  EXPECT_EQ(nr, 4);
  EXPECT_EQ(tau.size(), 32u);
  set.dims = {2, 4, 4};
  set.values.assign(32, 0.1);
  testing::write_h5(path("maps/cube.h5"), {set});
  testing::expect_error([&] { load_axial_plane_hdf5(path("maps/cube.h5"), "tau_v", nx, nr); },
                        {"cube.h5", "tau_v", "must be 2-D [nr][nx], found 3-D"});
}

TEST_F(AxialSceneFile, RefusesBadKeys) {
  refused("density", std::string(kAxial) + "[density]\nprocedural = {}\n", {"axial", "conflicts with [density]"});
  refused("unknown", axial_edited("nx = 64", "nx = 64\nradius = 3"), {"axial.radius", "unknown key"});
  refused("name", axial_edited("\"shells\"", "\"spiral\""), {"axial.synthetic", "'spiral'", "bipolar"});
  refused("two", axial_edited("nx = 64", "nx = 64\nfile = \"x.h5\""), {"axial.file", "conflicts with axial.synthetic"});
  refused("skip", axial_edited("nx = 64", "nx = 64\nskip = \"fast\""), {"axial.skip", "'fast'", "omega_multi"});
  refused("step", axial_edited("nx = 64", "nx = 64\nstep_texels = 0"), {"axial.step_texels", "must be > 0"});
  refused("axis", axial_edited("[0.0, 0.0, 2.0]", "[0.0, 0.0, 0.0]"), {"axial.axis", "must not be zero"});
  refused("off", axial_edited("[0.0, 0.0, 0.5]", "[0.1, 0.0, 0.5]"), {"stars.0.position", "from the axial map's axis"});
  refused("nx", axial_edited("nx = 64", "nx = 1"), {"axial.nx", "must be 2 to 65536"});
  refused("dataset", axial_edited("nx = 64", "nx = 64\ndataset = \"d\""), {"axial.dataset", "applies to axial.file only"});
  refused("missing", axial_edited("synthetic = \"shells\"\nnx = 64\nnr = 32", "file = \"none.h5\""),
          {"axial.file", "cannot read"});
  refused("override", kAxial, {"axial.step_texels", "override"}, {"axial.step_texels=-1"});
}

// Deformations (docs/scene.md, [axial.colour_deform] / [axial.shape_deform]):
// loaded key by key, off when absent, bad values refused naming the key, and
// the resolved scene (written into every output's metadata) carries them so
// that loading it again gives the same settings.
TEST_F(AxialSceneFile, DeformationsLoadValidateAndSaveBack) {
  const Scene plain = load_scene(write_text("plain.toml", kAxial));
  EXPECT_FALSE(plain.axial->colour_deform.on);
  EXPECT_FALSE(plain.axial->shape_deform.on);
  const std::string deform =
      "\n[axial.colour_deform]\nkind = \"cellular\"\nfrequency = 6.5\noctaves = 3\ngain = 0.4\nlacunarity = 2.5\n"
      "amplitude = 0.7\nseed = 42\n[axial.shape_deform]\nkind = \"turbulence\"\namplitude = 0.3\n";
  const std::string text = axial_edited("axis = [0.0, 0.0, 2.0]\n", "axis = [0.0, 0.0, 2.0]\n" + deform);
  const Scene s = load_scene(write_text("deform.toml", text));
  const AxialNoiseSpec& c = s.axial->colour_deform;
  EXPECT_TRUE(c.on);
  EXPECT_EQ(c.kind, "cellular");
  EXPECT_EQ(c.frequency, 6.5);
  EXPECT_EQ(c.octaves, 3);
  EXPECT_EQ(c.gain, 0.4);
  EXPECT_EQ(c.lacunarity, 2.5);
  EXPECT_EQ(c.amplitude, 0.7);
  EXPECT_EQ(c.seed, 42u);
  EXPECT_TRUE(s.axial->shape_deform.on);
  EXPECT_EQ(s.axial->shape_deform.kind, "turbulence");
  EXPECT_EQ(s.axial->shape_deform.amplitude, 0.3);
  EXPECT_EQ(s.axial->shape_deform.frequency, 4.0);  // the default
  // Saved back: the resolved scene holds the tables and loads to the same settings.
  EXPECT_NE(s.resolved_toml.find("colour_deform"), std::string::npos);
  const Scene again = load_scene(write_text("again.toml", s.resolved_toml));
  EXPECT_EQ(again.axial->colour_deform.kind, "cellular");
  EXPECT_EQ(again.axial->colour_deform.seed, 42u);
  EXPECT_EQ(again.axial->colour_deform.lacunarity, 2.5);
  EXPECT_EQ(again.axial->shape_deform.amplitude, 0.3);
  // Overrides reach the keys and are resolved too.
  const Scene o = load_scene(path("deform.toml"), {"axial.shape_deform.frequency=9"});
  EXPECT_EQ(o.axial->shape_deform.frequency, 9.0);
  EXPECT_NE(o.resolved_toml.find("frequency = 9"), std::string::npos) << o.resolved_toml;
  auto bad = [&](const std::string& from, const std::string& to, std::vector<std::string> pieces) {
    std::string t = text;
    const size_t at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    refused("bad", t, pieces);
  };
  bad("frequency = 6.5", "frequency = -2", {"axial.colour_deform.frequency", "is -2", "must be > 0"});
  bad("octaves = 3", "octaves = 0", {"axial.colour_deform.octaves", "1 to 8"});
  bad("gain = 0.4", "gain = 0", {"axial.colour_deform.gain", "(0, 1]"});
  bad("lacunarity = 2.5", "lacunarity = 0.5", {"axial.colour_deform.lacunarity"});
  bad("seed = 42", "seed = -1", {"axial.colour_deform.seed"});
  bad("\"cellular\"", "\"perlin\"", {"axial.colour_deform.kind", "'perlin'", "turbulence"});
  bad("amplitude = 0.3", "amplitude = 0.95", {"axial.shape_deform.amplitude", "[0, 0.9]"});
  bad("amplitude = 0.3", "amplitude = 0.3\nwarp = 1", {"axial.shape_deform.warp", "unknown key"});
}

// Issue 17, item 7: a scene with both [axial] and [density] in the file names
// no override, even when an unrelated axial key was overridden; an override
// that made the conflicting table is named.
TEST_F(AxialSceneFile, DensityConflictBlamesOnlyTheOverrideThatMadeIt) {
  const std::string both = write_text("both.toml", std::string(kAxial) + "[density]\nprocedural = {}\n");
  try {
    load_scene(both, {"axial.step_texels=1"});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("conflicts with [density]"), std::string::npos) << m;
    EXPECT_EQ(m.find("override"), std::string::npos) << m;
  }
  refused("made", kAxial, {"axial", "conflicts with [density]", "density.scale=2"}, {"density.scale=2"});
}

// Issue 17, item 6: values whose consequences overflow single precision are
// refused up front, naming the key (they rendered, then failed naming no key).
TEST_F(SceneFile, RefusesValuesThatOverflowTheImage) {
  refused("luminosity", edited("luminosity_lsun = 2e5", "luminosity_lsun = 1e300"),
          {"stars.0.luminosity_lsun", "1e+300", "at most"});
  refused("exposure", edited("look_at = [1.0, 1.0, 1.0]\n", "look_at = [1.0, 1.0, 1.0]\nexposure = 1e38\n"),
          {"camera.exposure", "1e+38", "at most"});
}

// Issue 17, item 7: a camera far away is called far away, not "look_at equals
// position".
TEST_F(SceneFile, FarCameraIsCalledFar) {
  const std::string far = edited("position = [1.0, -3.0, 1.0]", "position = [1e30, 1e30, 1e30]");
  refused("far", far, {"camera.position", "farther than"});
  const std::string text = write_text("far2.toml", far);
  try {
    load_scene(text);
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find("equals the position"), std::string::npos) << e.what();
  }
}

// Issue 17, item 7: a FITS origin beyond single precision names the file.
TEST_F(SceneFile, FitsOriginOutOfRangeNamesTheFile) {
  testing::FitsKeys keys;
  keys.numbers = {{"CDELT1", 0.5}, {"CDELT2", 0.5}, {"CDELT3", 0.5}, {"CRPIX1", 1}, {"CRPIX2", 1}, {"CRPIX3", 1},
                  {"CRVAL1", 1e308}, {"CRVAL2", 0}, {"CRVAL3", 0}};
  write_fits(path("far.fits"), {2, 2, 2}, std::vector<double>(8, 0.1), -32, keys);
  expect_error([&] { load_density_fits(path("far.fits")); }, {"far.fits", "CRVAL1"});
  refused("fits", edited("procedural = { n = 16, size_pc = 2.0, seed = 3 }", "fits = \"far.fits\""),
          {"density.fits", "far.fits", "CRVAL1"});
}

}  // namespace
}  // namespace nebula
