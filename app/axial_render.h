#pragma once
// `nebula render` for a scene with an [axial] map: builds the map, bakes the
// stars on its axis, renders with the axial marcher and writes the image.
// render_command.cpp hands such scenes over here.
#include <string>

#include "raycast/axial_map.h"
#include "scene/scene.h"

namespace nebula::app {

struct AxialCommandOptions {
  std::string out, backend = "auto", table_photons = "3e4";
  bool force = false, quiet = false;
  int width = 0, height = 0;  // 0: the scene's
  float smooth = 0;           // refused unless 0 (the axial march has its own step)
};

// The map a scene's [axial] table describes (synthetic, HDF5 or image), with
// its skip structures; Error naming the key and the reason otherwise
// (app/axial_map_source.cpp).
AxialMap build_axial_map(const Scene& scene);

void run_axial_render(Scene& scene, const AxialCommandOptions& o);

}  // namespace nebula::app
