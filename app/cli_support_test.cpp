#include "app/cli_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <fstream>

#include "core/error.h"
#include "scene/scene_file.h"
#include "scene/test_files.h"

namespace nebula::app {
namespace {

TEST(OutputPath, RefusesExistingMissingFolderAndFolders) {
  const auto dir = std::filesystem::temp_directory_path() / "nebula_output_path_test";
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "exists.h5").string();
  std::ofstream(file) << "x";
  EXPECT_THROW(check_output_path("-o", file, false), Error);
  EXPECT_NO_THROW(check_output_path("-o", file, true));
  EXPECT_THROW(check_output_path("-o", (dir / "missing" / "t.h5").string(), false), Error);
  EXPECT_THROW(check_output_path("-o", dir.string(), true), Error);
  EXPECT_NO_THROW(check_output_path("-o", (dir / "new.h5").string(), false));
  std::filesystem::remove_all(dir);
}

TEST(OutputPath, ParsesCounts) {
  EXPECT_EQ(parse_count("--photons", "1e6", 2, 1e9), 1000000u);
  EXPECT_EQ(parse_count("--photons", "250", 2, 1e9), 250u);
  EXPECT_THROW(parse_count("--photons", "0", 2, 1e9), Error);
  EXPECT_THROW(parse_count("--photons", "1.5", 1, 1e9), Error);
  EXPECT_THROW(parse_count("--photons", "ten", 1, 1e9), Error);
  EXPECT_THROW(parse_count("--photons", "1e6x", 1, 1e9), Error);
  EXPECT_THROW(parse_count("--photons", "1e12", 1, 1e9), Error);
}

// Library errors name the parameter; the command names the option that set it,
// or the scene file for a scene key, and leaves other errors alone.
TEST(NamingOptions, RewordsParameterErrors) {
  const OptionNames names{{"albedo", "--albedo"}, {"smooth_step", "--smooth"}};
  auto message = [&](const std::function<void()>& body, const std::string& context = "") {
    try {
      naming_options(names, body, context);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([] { throw ParameterError("albedo", "must be in [0, 1], got 2"); }),
            "--albedo: must be in [0, 1], got 2");
  EXPECT_EQ(message([] { throw ParameterError("render.levels", "9 exceeds the 6"); }, "a.toml"),
            "a.toml: render.levels: 9 exceeds the 6");
  EXPECT_EQ(message([] { throw ParameterError("render.levels", "9 exceeds the 6"); }), "render.levels: 9 exceeds the 6");
  EXPECT_EQ(message([] { throw Error("plain"); }, "a.toml"), "plain");
  EXPECT_EQ(message([] {}), "no error");
}

// Issue 17: -o naming the scene's density file (by any name) is refused, even
// with --force; a file that is no input passes.
class OutputInput : public nebula::testing::TempDirTest {};

TEST_F(OutputInput, RefusesTheDensityFileByAnyName) {
  nebula::testing::H5Dataset set;
  set.dims = {2, 2, 2};
  set.values.assign(8, 0.5);
  set.voxel_size = 0.1;
  nebula::testing::write_h5(path("dens.h5"), {set});
  const std::string scene_path = write_text(
      "scene.toml", "[density]\nfile = \"dens.h5\"\n[[stars]]\nposition = [0.1, 0.1, 0.1]\nluminosity_lsun = 1\n"
                    "class = \"G2V\"\n[camera]\nposition = [0.1, -3, 0.1]\nlook_at = [0.1, 0.1, 0.1]\n");
  const Scene scene = load_scene(scene_path);
  nebula::testing::expect_error([&] { check_not_an_input("-o", path("dens.h5"), scene.inputs); },
                                {"-o", "dens.h5", "density.file"});
  std::filesystem::create_hard_link(path("dens.h5"), path("other_name.h5"));
  nebula::testing::expect_error([&] { check_not_an_input("-o", path("other_name.h5"), scene.inputs); },
                                {"-o", "other_name.h5", "density.file"});
  nebula::testing::expect_error([&] { check_not_an_input("-o", scene_path, scene.inputs); }, {"the scene file"});
  std::ofstream(path("image.h5")) << "x";
  EXPECT_NO_THROW(check_not_an_input("-o", path("image.h5"), scene.inputs));
  EXPECT_NO_THROW(check_not_an_input("-o", path("new.h5"), scene.inputs));
}

}  // namespace
}  // namespace nebula::app
