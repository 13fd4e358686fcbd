#include "app/cli_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <fstream>

#include "core/error.h"

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

}  // namespace
}  // namespace nebula::app
