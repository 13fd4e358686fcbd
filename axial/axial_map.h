#pragma once
// Axial-symmetric nebulae (DESIGN.md section 3, "Axial map"; Khalass 2021,
// TU Delft MSc thesis): a 2D map M(x, r) rotated about an axis. x runs along
// the axis from the map's origin, r is the distance from the axis. Texels are
// squares of edge l; tau_v is the V-band extinction depth across one texel
// edge and emission j_b the radiance a ray gains crossing one texel edge, the
// same quantities as a voxel's (the texel plays the voxel's part).
//
// For empty-space skipping the map carries, per x-column, the height map
// h[ix] = 1 + the highest non-empty r index (0 for an empty column), its
// global maximum H and a max-tree over h; and the floor map f[ix] = the
// lowest non-empty r index (kAxialEmptyFloor for an empty column) with a min-tree, for the
// hollow inside of shells and lobes. Beyond the thesis, every texel carries
// its Chebyshev distance (in texels) to the nearest non-empty texel, the
// proximity clouds of Cohen & Sheffer (1994), for the `distance` skip mode:
// one byte per texel, so the map stays small in the caches.
// Empty means tau_v == 0 and every band's emission == 0.
#include <cstdint>
#include <string>
#include <vector>

#include "core/bands.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

constexpr int kAxialMaxTreeLevels = 32;
constexpr int kAxialEmptyFloor = 1 << 30;  // the floor of an empty column: every r is below it
constexpr int kAxialMaxDistance = 255;     // the distance map's cap (a lower bound beyond it)

// A non-owning view for kernels (host or device pointers), by value.
struct AxialView {
  int nx = 0, nr = 0;     // texels along the axis and radially
  float texel = 1;        // edge l, world units
  Vec3 origin;            // the axis point where x = 0
  Vec3 axis{0, 0, 1};     // unit direction of +x
  const float* tau_v = nullptr;                   // [ir * nx + ix]
  const float* emission[kMaxBands] = {};     // same layout, or null
  const int* height = nullptr;                    // [ix], 0..nr
  const int* floor = nullptr;                     // [ix]: lowest non-empty r index, kAxialEmptyFloor for an empty column
  const int* tree = nullptr;                      // max-tree levels, level 0 = height padded
  const int* floor_tree = nullptr;                // min-tree of floor, same levels (padded with kAxialEmptyFloor)
  int level_offset[kAxialMaxTreeLevels] = {};     // start of each level in `tree`
  int n_levels = 0;
  int global_max = 0;                             // H = max over h
  // [ir * nx + ix]: max(|jx - ix|, |jr - ir|) to the nearest non-empty texel
  // (jx, jr), 0 for a non-empty texel, capped at kAxialMaxDistance.
  const uint8_t* distance = nullptr;

  NEBULA_HD size_t index(int ix, int ir) const { return size_t(ir) * nx + ix; }
  NEBULA_HD float length() const { return nx * texel; }
  NEBULA_HD float radius() const { return nr * texel; }

  // Largest h over columns [lo, hi] (clamped to the map; 0 when the range
  // lies outside it), O(log nx) over the max-tree.
  NEBULA_HD int range_max_tree(int lo, int hi) const {
    lo = lo < 0 ? 0 : lo;
    hi = hi >= nx ? nx - 1 : hi;
    int m = 0;
    for (int level = 0; lo <= hi && level < n_levels; ++level) {
      const int* h = tree + level_offset[level];
      if (lo & 1) {
        m = h[lo] > m ? h[lo] : m;
        ++lo;
      }
      if (!(hi & 1)) {
        m = h[hi] > m ? h[hi] : m;
        --hi;
      }
      lo >>= 1;
      hi >>= 1;
    }
    return m;
  }

  // Smallest floor over columns [lo, hi] (clamped; kAxialEmptyFloor when outside), O(log nx).
  NEBULA_HD int range_min_floor(int lo, int hi) const {
    lo = lo < 0 ? 0 : lo;
    hi = hi >= nx ? nx - 1 : hi;
    int m = kAxialEmptyFloor;
    for (int level = 0; lo <= hi && level < n_levels; ++level) {
      const int* f = floor_tree + level_offset[level];
      if (lo & 1) {
        m = f[lo] < m ? f[lo] : m;
        ++lo;
      }
      if (!(hi & 1)) {
        m = f[hi] < m ? f[hi] : m;
        --hi;
      }
      lo >>= 1;
      hi >>= 1;
    }
    return m;
  }

  // The same by scanning the height map (the plain omega-step).
  NEBULA_HD int range_max_scan(int lo, int hi) const {
    lo = lo < 0 ? 0 : lo;
    hi = hi >= nx ? nx - 1 : hi;
    int m = 0;
    for (int i = lo; i <= hi; ++i) m = height[i] > m ? height[i] : m;
    return m;
  }
};

// The owning map. After filling tau_v / emission call update_skip_structures.
struct AxialMap {
  int nx = 0, nr = 0;
  float texel = 1;
  Vec3 origin;
  Vec3 axis{0, 0, 1};
  std::vector<float> tau_v;                  // [ir * nx + ix]
  std::vector<std::vector<float>> emission;  // empty, or one per band
  // Derived (update_skip_structures):
  std::vector<int> height;
  std::vector<int> floor;       // lowest non-empty r index per column (kAxialEmptyFloor: empty column)
  std::vector<int> tree;
  std::vector<int> floor_tree;  // min-tree of floor, levels as tree's
  std::vector<int> level_offset;
  std::vector<uint8_t> distance;  // Chebyshev distance to the nearest non-empty texel (AxialView::distance)
  int global_max = 0;
  size_t empty_texels = 0;  // texels with no dust and no emission

  size_t count() const { return size_t(nx) * nr; }
  float length() const { return nx * texel; }
  float radius() const { return nr * texel; }
  size_t index(int ix, int ir) const { return size_t(ir) * nx + ix; }
  bool empty_at(size_t i) const;

  // Recomputes height, floor, their trees, global_max and the distance map
  // from tau_v and emission.
  void update_skip_structures();
  void update_distance_map();  // part of update_skip_structures
  // A host view (pointers into this map).
  AxialView view() const;
  // Bytes of the map with its skip structures (the memory the renderer uploads).
  size_t bytes() const;
};

// Throws Error "<what>: <reason>" on sizes that disagree, a non-unit or zero
// axis, a texel <= 0, or NaN, infinite or negative values.
void check_axial_map(const AxialMap& map, const std::string& what);

// The map voxelized to a 3D grid of edge `voxel` spanning the cylinder's
// bounding box: each voxel takes the texel holding its centre's (x, r), zero
// outside the map; tau_v is rescaled from per texel edge to per voxel edge.
// `emission` (may be null) receives one grid per emission band, rescaled alike.
struct DensityGrid;
DensityGrid voxelize_axial_map(const AxialMap& map, float voxel, std::vector<std::vector<float>>* emission);

// The built-in maps, after the thesis' cases (docs/axial.md, "Maps", states
// their empty fractions): "bipolar" (two thin-walled lobes, like M2-9: mostly
// empty), "lopsided" (like the Calabash nebula: a dense off-centre core with a
// long lobe to one side and a short one to the other, most texels empty),
// "shells" (round, like NGC 6826: three concentric shells, the inner one
// emitting), "empty", "full" (dust and emission in every texel) and "cloud"
// (the lopsided map before issue 15: a dense cloud with a tail). `tau_scale` multiplies tau_v
// (which is given per map radius, so the optical depths do not depend on
// nr); emission gets `n_emission_bands` planes (0: none). The map is
// nx x nr texels of edge `texel`, its axis through `origin` along `axis`.
AxialMap synthetic_axial_map(const std::string& name, int nx, int nr, float texel, int n_emission_bands = 0,
                             float tau_scale = 1.0f);
const std::vector<std::string>& synthetic_axial_map_names();

}  // namespace nebula
