#pragma once
// The axial map a scene's [axial] table describes (docs/scene.md): a built-in
// synthetic map, 2D datasets of an HDF5 file, or the channels of an image,
// scaled, checked and with its skip structures built.
#include "axial/axial_map.h"
#include "scene/scene.h"

namespace nebula {

// Error naming the scene key and the reason for a map that cannot be built.
AxialMap build_axial_map(const Scene& scene);

// A map given in memory for an [axial] scene (the viewer's painted one): its
// values taken as they are (no axial.tau_scale or emission_scale), its texel
// axial.length_pc / nx, its origin and axis the scene's. Error naming the
// scene's key when its emission planes are not one per band or
// axial.step_texels exceeds it.
AxialMap place_axial_map(const Scene& scene, AxialMap map);

}  // namespace nebula
