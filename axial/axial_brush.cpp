#include "axial/axial_brush.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace nebula {

const char* to_string(BrushShape shape) { return shape == BrushShape::Round ? "round" : "square"; }

const char* to_string(BrushMode mode) {
  return mode == BrushMode::Set ? "set" : mode == BrushMode::Add ? "add" : "erase";
}

bool parse_brush_shape(const std::string& name, BrushShape& out) {
  if (name == "round") return out = BrushShape::Round, true;
  if (name == "square") return out = BrushShape::Square, true;
  return false;
}

bool parse_brush_mode(const std::string& name, BrushMode& out) {
  if (name == "set") return out = BrushMode::Set, true;
  if (name == "add") return out = BrushMode::Add, true;
  if (name == "erase") return out = BrushMode::Erase, true;
  return false;
}

void check_brush(const Brush& b, const AxialMap& map) {
  auto fail = [](const std::string& what, const std::string& reason) { throw Error("brush: " + what + ": " + reason); };
  if (!(std::isfinite(b.radius) && b.radius > 0)) fail("radius", "is " + to_text(b.radius) + "; must be > 0 texels");
  if (!std::isfinite(b.value)) fail("value", "must be a finite number");
  if (b.mode == BrushMode::Set && b.value < 0) fail("value", "is " + to_text(b.value) + "; set needs >= 0");
  if (b.n_bands < 0) fail("bands", "negative count");
  if (!b.plane.is_tau() && b.plane.band >= b.n_bands)
    fail("plane", "band " + std::to_string(b.plane.band) + " is not one of the scene's " + std::to_string(b.n_bands));
  if (!map.emission.empty() && map.emission.size() != size_t(b.n_bands))
    fail("plane", "the map has " + std::to_string(map.emission.size()) + " emission planes for " +
                      std::to_string(b.n_bands) + " bands");
  if (map.nx <= 0 || map.nr <= 0 || map.tau_v.size() != map.count()) fail("map", "is empty or its sizes disagree");
}

namespace {

// One dab; the texels it covers counted into `r`.
void dab(AxialMap& map, const Brush& b, BrushPoint p, PaintResult& r) {
  const int held_x = int(std::floor(p.x)), held_r = int(std::floor(p.r));
  const int x0 = std::max(0, std::min(held_x, int(std::floor(p.x - b.radius))) - 1);
  const int x1 = std::min(map.nx - 1, std::max(held_x, int(std::floor(p.x + b.radius))) + 1);
  const int r0 = std::max(0, std::min(held_r, int(std::floor(p.r - b.radius))) - 1);
  const int r1 = std::min(map.nr - 1, std::max(held_r, int(std::floor(p.r + b.radius))) + 1);
  for (int ir = r0; ir <= r1; ++ir)
    for (int ix = x0; ix <= x1; ++ix) {
      const double dx = ix + 0.5 - double(p.x), dr = ir + 0.5 - double(p.r);
      const double d = b.shape == BrushShape::Round ? std::sqrt(dx * dx + dr * dr) : std::max(std::fabs(dx), std::fabs(dr));
      const bool held = ix == held_x && ir == held_r;
      if (!(d <= b.radius) && !held) continue;
      const float w = b.soft ? float(std::max(0.0, 1.0 - d / b.radius)) : 1.0f;
      ++r.texels;
      if (r.x1 < r.x0) {
        r.x0 = r.x1 = ix;
        r.r0 = r.r1 = ir;
      } else {
        r.x0 = std::min(r.x0, ix), r.x1 = std::max(r.x1, ix);
        r.r0 = std::min(r.r0, ir), r.r1 = std::max(r.r1, ir);
      }
      const size_t i = map.index(ix, ir);
      if (b.mode == BrushMode::Erase) {
        map.tau_v[i] *= 1.0f - w;
        for (auto& plane : map.emission) plane[i] *= 1.0f - w;
        continue;
      }
      float& v = b.plane.is_tau() ? map.tau_v[i] : map.emission[size_t(b.plane.band)][i];
      if (b.mode == BrushMode::Set)
        v = w == 1.0f ? b.value : v + w * (b.value - v);
      else
        v = std::max(0.0f, v + w * b.value);
    }
}

}  // namespace

PaintResult paint_axial_map(AxialMap& map, const Brush& brush, const std::vector<BrushPoint>& dabs) {
  check_brush(brush, map);
  for (const BrushPoint& p : dabs)
    if (!std::isfinite(p.x) || !std::isfinite(p.r)) throw Error("brush: a dab's position is not finite");
  if (!brush.plane.is_tau() && brush.mode != BrushMode::Erase && map.emission.empty())
    map.emission.assign(size_t(brush.n_bands), std::vector<float>(map.count(), 0.0f));
  PaintResult r;
  for (const BrushPoint& p : dabs) dab(map, brush, p, r);
  map.update_skip_structures();
  return r;
}

std::vector<BrushPoint> brush_segment(BrushPoint a, BrushPoint b, float radius) {
  const float spacing = std::max(0.25f, 0.25f * radius);
  const float len = std::hypot(b.x - a.x, b.r - a.r);
  const int n = std::max(1, int(std::ceil(len / spacing)));
  std::vector<BrushPoint> out;
  for (int k = 1; k <= n; ++k) {
    const float t = float(k) / float(n);
    out.push_back({a.x + t * (b.x - a.x), a.r + t * (b.r - a.r)});
  }
  return out;
}

}  // namespace nebula
