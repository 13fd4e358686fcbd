#include "app/cli_support.h"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>

#include "core/error.h"
#include "core/gpu.h"
#include "imageio/image_output.h"
#include "scene/scene_file.h"

namespace nebula::app {

void check_output_path(const std::string& option, const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  if (path.empty()) throw Error(option + ": an output file is required");
  const fs::path p(path);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw Error(option + ": " + path + " is a folder, not a file");
  if (fs::exists(p, ec) && !overwrite)
    throw Error(option + ": " + path + " exists; pass --force to overwrite it");
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw Error(option + ": folder " + dir.string() + " does not exist");
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(option + ": cannot write into folder " + dir.string() + " (permission denied)");
}

void check_not_an_input(const std::string& option, const std::string& path, const std::vector<SceneInput>& inputs) {
  namespace fs = std::filesystem;
  for (const SceneInput& input : inputs) {
    std::error_code ec;
    if (fs::equivalent(path, input.path, ec))  // false (with ec set) when either does not exist
      throw Error(option + ": " + path + " is " +
                  (input.key == "scene" ? "the scene file" : "the scene's input " + input.key + " (" + input.path + ")") +
                  "; writing it would destroy an input, choose another output");
  }
}

void check_image_output(const std::string& option, const std::string& path, bool overwrite) {
  try {
    check_image_format(path);
  } catch (const Error& e) {
    throw Error(option + ": " + e.what());
  }
  check_output_path(option, path, overwrite);
}

uint64_t parse_count(const std::string& option, const std::string& text, double lo, double hi) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (...) {
    used = 0;
  }
  if (used != text.size() || text.empty())
    throw Error(option + ": expected a number such as 1e6, got '" + text + "'");
  if (!(v >= lo && v <= hi) || v != std::floor(v))
    throw Error(option + ": expected a whole number from " + std::to_string(uint64_t(lo)) + " to " +
                std::to_string(uint64_t(hi)) + ", got '" + text + "'");
  return static_cast<uint64_t>(v);
}

Backend parse_backend(const std::string& s, const std::string& option) {
  if (s == "cpu") return Backend::Cpu;
  if (s == "cuda" || s == "gpu") {
    std::string why;
    if (!gpu_available(&why)) throw Error(option + ": " + s + " requested but " + why);
    return Backend::Cuda;
  }
  if (s == "auto") return gpu_available() ? Backend::Cuda : Backend::Cpu;
  throw Error(option + ": expected cpu, cuda or auto, got '" + s + "'");
}

std::vector<Backend> bench_backends(const std::string& text) {
  if (text == "both" || (text == "auto" && gpu_available())) return {Backend::Cpu, Backend::Cuda};
  return {parse_backend(text)};
}

void add_scene_options(CLI::App* command, SceneOptions& o) {
  command->add_option("SCENE", o.path, "scene file (docs/scene.md)");
  command->add_flag("--demo", o.demo, "the built-in procedural nebula with an O-type star (scenes/demo.toml)");
  command->add_option("--set", o.overrides, "KEY=VALUE scene override, e.g. camera.fov_deg=30 (repeatable)")
      ->allow_extra_args(false);
  command->add_option("--width", o.width, "image width (overrides the scene)");
  command->add_option("--height", o.height, "image height (overrides the scene)");
}

Scene load_scene_options(const std::string& command, const SceneOptions& o) {
  if (o.demo == !o.path.empty()) throw Error(command + ": give a SCENE.toml or --demo (one of them)");
  if (o.demo && !o.overrides.empty())
    throw Error("--set: the demo takes no overrides; copy scenes/demo.toml and pass it instead");
  for (const auto& [option, value] : {std::pair<const char*, int>{"--width", o.width}, {"--height", o.height}})
    if (value != -1 && !(value >= 1 && value <= kMaxCameraPixels))
      throw Error(std::string(option) + ": is " + std::to_string(value) + "; must be 1 to " +
                  std::to_string(kMaxCameraPixels) + " pixels");
  Scene scene = o.demo ? demo_scene() : load_scene(o.path, o.overrides);
  if (o.width != -1) scene.camera.width = o.width;
  if (o.height != -1) scene.camera.height = o.height;
  return scene;
}

void naming_options(const OptionNames& options, const std::function<void()>& body, const std::string& context) {
  try {
    body();
  } catch (const ParameterError& e) {
    const auto option = options.find(e.parameter());
    if (option != options.end()) throw Error(option->second + ": " + e.reason());
    if (!context.empty()) throw Error(context + ": " + e.what());
    throw;
  }
}

}  // namespace nebula::app
