#pragma once
// Painting an axial map M(x, r) with a brush (Khalass 2021, section 4.1: the
// user paints the 2D map and watches the nebula change). A dab edits the
// texels under the brush in one plane, tau_v or one band's emission; erase
// empties texels (every plane). The skip structures are rebuilt after the
// stroke, so the renderer's empty-space skipping stays exact.
#include <cstddef>
#include <string>
#include <vector>

#include "axial/axial_map.h"

namespace nebula {

enum class BrushShape { Round, Square };
enum class BrushMode { Set, Add, Erase };
const char* to_string(BrushShape shape);  // "round", "square"
const char* to_string(BrushMode mode);    // "set", "add", "erase"
bool parse_brush_shape(const std::string& name, BrushShape& out);
bool parse_brush_mode(const std::string& name, BrushMode& out);

// Which plane a brush paints: tau_v, or the emission of band `band` (an index
// into the scene's bands; painting emission on a map without emission planes
// gives it zero planes for every band first).
struct BrushPlane {
  int band = -1;  // -1: tau_v
  bool is_tau() const { return band < 0; }
};

struct Brush {
  BrushShape shape = BrushShape::Round;
  bool soft = false;   // weight 1 - d / radius instead of 1 inside the footprint
  BrushMode mode = BrushMode::Set;
  float radius = 4;    // texels, > 0
  float value = 1;     // tau_v per texel edge or emission per texel edge; Set: >= 0
  BrushPlane plane;
  int n_bands = 0;     // the scene's bands (emission planes made on demand have this many)
};

// One dab's centre in texel coordinates: x along the axis, r from it; the
// texel (ix, ir) spans [ix, ix + 1) x [ir, ir + 1), its centre (ix + 0.5, ir + 0.5).
struct BrushPoint {
  float x = 0, r = 0;
};

// The footprint: texels whose centre lies within `radius` of the dab's
// centre (Euclidean for round, the larger axis distance for square), plus
// the texel holding the centre (a radius below half a texel still paints
// one). Texels outside the map are left out (no wrap, no mirror at r = 0).
// The weight w is 1, or with `soft` max(0, 1 - d / radius) (the held texel
// included: a soft dab smaller than a texel may change nothing).
// Set: v += w (value - v); Add: v = max(0, v + w value); Erase: every plane
// of the texel times (1 - w), so a hard erase leaves it empty.
struct PaintResult {
  size_t texels = 0;                     // texels in the footprints (counted once per dab)
  int x0 = 0, x1 = -1, r0 = 0, r1 = -1;  // the bounding box touched, inclusive (empty: x1 < x0)
};

// Throws Error "brush: <what>: <reason>" for a radius <= 0 or not finite, a
// value not finite (or negative for Set), a band outside 0..n_bands-1, or a
// map whose emission planes disagree with n_bands. Edits nothing then.
void check_brush(const Brush& brush, const AxialMap& map);

// Paints the dabs in order (a stroke: the mouse's path), then rebuilds the
// map's skip structures once (AxialMap::update_skip_structures).
PaintResult paint_axial_map(AxialMap& map, const Brush& brush, const std::vector<BrushPoint>& dabs);

// The dabs along a segment from a to b, spaced a quarter of the radius (at
// least a texel / 4) apart, a excluded and b included: a mouse drag painted
// without gaps.
std::vector<BrushPoint> brush_segment(BrushPoint a, BrushPoint b, float radius);

}  // namespace nebula
