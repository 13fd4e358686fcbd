#pragma once
// The axial map a scene's [axial] table describes (docs/scene.md): a built-in
// synthetic map, 2D datasets of an HDF5 file, or the channels of an image,
// scaled, checked and with its skip structures built.
#include "axial/axial_map.h"
#include "scene/scene.h"

namespace nebula {

// Error naming the scene key and the reason for a map that cannot be built.
AxialMap build_axial_map(const Scene& scene);

}  // namespace nebula
