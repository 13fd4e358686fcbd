#pragma once
// Scene files: TOML (docs/scene.md documents every key), read with toml++.
#include <string>
#include <vector>

#include "scene/density_sources.h"
#include "scene/scene.h"

namespace nebula {

// Reads, overrides, checks and loads a scene: the density (and emission)
// grids are read or generated here. `overrides` are "KEY=VALUE" strings
// applied in order to the parsed file before any check: KEY is a dotted path
// (camera.fov_deg, dust.albedo.B, density.procedural.seed), with array
// elements addressed by a 0-based index (stars.0.luminosity_lsun; the index
// one past the end appends a star); VALUE is a TOML value (30, 1e4, true,
// [1, 2, 3], {B = 0.7, V = 0.6, R = 0.5}, "text"), and text that is not valid
// TOML is taken as a string (camera.kind=fisheye). Every problem is an Error
// of one line, "<file>: <key>: <reason>", with "(set by override 'K=V')"
// appended when an override supplied the key.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// The same, from TOML text; `name` stands for the file in messages and
// `base_dir` resolves relative data paths. With `reuse_grids`, a scene whose
// grids come from the same [density] and [emission] tables, bands and folder
// (Scene::grid_source) copies that scene's grids instead of reading or
// generating them again (edits and sweeps; files changed on disk meanwhile
// are not seen).
Scene load_scene_text(const std::string& text, const std::string& name,
                      const std::string& base_dir, const std::vector<std::string>& overrides = {},
                      const Scene* reuse_grids = nullptr);

// A scene's TOML text (such as Scene::resolved_toml) with its [axial] map
// read from an HDF5 file instead (the viewer's painted map, saved): the keys
// naming the map (synthetic, nx, nr, file, image, dataset, emission_prefix,
// tau_channel, emission_channels) give way to file = `file`, dataset =
// "tau_v", emission_prefix = `emission_prefix` (when not empty), and
// tau_scale = emission_scale = 1 (the file holds the values as rendered);
// every other key stays as written. Error when the text has no [axial] table.
std::string scene_text_with_axial_file(const std::string& text, const std::string& file,
                                       const std::string& emission_prefix);

// A scene's TOML text without some keys, each a dotted path ("bands",
// "spectral.range_um"; one not there is passed over), printed as toml++
// prints it: two scenes that differ only in those keys give equal texts.
// Error when the text is not TOML.
std::string scene_text_without(const std::string& text, const std::vector<std::string>& keys);

// The built-in demo (`nebula render --demo`), equal to scenes/demo.toml: a
// procedural nebula tuned to show structure (128^3 voxels, 2 pc; the star
// off-centre, filaments, docs/scene.md), one O5V star of 2e5 L_sun at the
// procedural star, a 512 x 512 perspective camera on the near side (-y)
// looking past the star, dust a = g = 0.6, R_V = 5 (CCM89), an asinh display
// with auto exposure, and a camera path for `nebula animate --demo`.
ProceduralParams demo_procedural_params();
Scene demo_scene();

}  // namespace nebula
