#pragma once
// What every command of the `nebula` command line does the same way: refuse
// outputs before any work, read counts such as 1e6, and name its own options
// in the errors the libraries raise about the parameters those options set.
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/backend.h"
#include "imageio/image_output.h"
#include "scene/scene.h"

namespace nebula::app {

// Refuses, before any work starts, an output that exists (unless overwrite),
// lives in a missing or unwritable folder, or is a folder. Throws Error
// naming the option and the path.
void check_output_path(const std::string& option, const std::string& path, bool overwrite);

// Refuses an output that is one of the files the run reads (the same file by
// device and inode, whatever its name: std::filesystem::equivalent), with or
// without --force. Throws Error naming the option, the path and the input's key.
void check_not_an_input(const std::string& option, const std::string& path, const std::vector<SceneInput>& inputs);

// check_output_path, and a format the image writer cannot write here.
void check_image_output(const std::string& option, const std::string& path, bool overwrite);

// 1e6-style numbers for photon counts: a whole number in [lo, hi].
uint64_t parse_count(const std::string& option, const std::string& text, double lo, double hi);

// --backend: "cpu", "cuda" (or "gpu") or "auto" (CUDA when a device is usable).
Backend parse_backend(const std::string& text, const std::string& option = "--backend");

// "cpu" or "cuda" for --backend both/auto in benchmarks: both when a GPU is
// present (auto) or asked for (both), else the one parse_backend gives.
std::vector<Backend> bench_backends(const std::string& text);

// The scene a rendering command reads: SCENE or --demo (exactly one), its
// --set overrides and --width/--height (0: the scene's).
struct SceneOptions {
  std::string path;
  bool demo = false;
  std::vector<std::string> overrides;
  int width = -1, height = -1;  // -1: not given (the scene's)
};
// Registers SCENE, --demo, --set (repeatable, one value each: a scene file
// after it is never taken for another override), --width and --height.
void add_scene_options(CLI::App* command, SceneOptions& options);
Scene load_scene_options(const std::string& command, const SceneOptions& options);

// A library parameter (ParameterError::parameter) -> the option that set it.
using OptionNames = std::map<std::string, std::string>;

// Runs `body`. A ParameterError whose parameter one of `options` set is
// rethrown as Error("<option>: <reason>"); any other one (a scene key) as
// Error("<context>: <parameter>: <reason>") when `context` (the scene file)
// is given. Other errors pass unchanged.
void naming_options(const OptionNames& options, const std::function<void()>& body, const std::string& context = "");

// A sweep axis from "KEY=START:STOP:COUNT" or "KEY=V1,V2,..." (`nebula sweep
// --grid`); Error naming --grid and the reason (app/sweep_command.cpp).
CubeAxis parse_grid_axis(const std::string& spec);

}  // namespace nebula::app
