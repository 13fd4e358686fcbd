#pragma once
// The bands one render carries, and what the dust and the stars do in each
// (DESIGN.md section 3, "Bands"). A band is named by its filter ("B", "V", "R";
// the filter registry, illumination/filters.h, knows which names exist); every
// renderer takes its bands and stars as these types, adding only what it reads
// itself (tables, emission grids, baked depths).
#include <string>
#include <vector>

#include "core/device_mirror.h"
#include "core/vec3.h"

namespace nebula {

// The most bands one render carries: kernels keep per-band arrays of this
// size in registers (DESIGN.md, "Band loops in kernels").
constexpr int kMaxBands = 4;

// The band of one-wavelength (grey) radiative transfer, as benchmarks use: no
// filter, the star's whole luminosity, A/A_V = 1 (pipeline/scene_bands.h).
inline constexpr const char* kGreyBand = "grey";

// One band: its filter and the dust's optical properties in it.
struct Band {
  std::string name;            // the filter's name, e.g. "V"
  float extinction_ratio = 1;  // A_b / A_V: tau_b = tau_v * extinction_ratio
  float albedo = 0.6f;         // single-scattering albedo a_b; 0: the band does not scatter
  float g = 0.6f;              // Henyey-Greenstein asymmetry g_b
};

// A point star as every renderer sees it: where it is and its power per band
// (L_sun inside each band, in the bands' order).
struct StarLight {
  Vec3 position;
  std::vector<float> power;
};

// The bands' names in order: the planes of every image a renderer makes.
template <class AnyBand>
std::vector<std::string> band_names(const std::vector<AnyBand>& bands) {
  std::vector<std::string> names;
  for (const Band& b : bands) names.push_back(b.name);
  return names;
}

// A star with its baked V-band optical depth to every cell of the volume a
// renderer marches (voxels of a grid, texels of an axial map).
struct BakedStar : StarLight {
  const std::vector<float>* depth_v = nullptr;
  DeviceMirror* depth_mirror = nullptr;  // the CUDA kernels' copy of *depth_v, kept by its owner; null: uploaded per render
};

}  // namespace nebula
