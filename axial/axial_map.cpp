#include "axial/axial_map.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/grid.h"
#include "core/math.h"

namespace nebula {

bool AxialMap::empty_at(size_t i) const {
  if (tau_v[i] != 0.0f) return false;
  for (const std::vector<float>& e : emission)
    if (e[i] != 0.0f) return false;
  return true;
}

void AxialMap::update_skip_structures() {
  height.assign(size_t(nx), 0);
  empty_texels = 0;
  for (size_t i = 0; i < count(); ++i) empty_texels += empty_at(i);
  for (int ix = 0; ix < nx; ++ix)
    for (int ir = nr - 1; ir >= 0; --ir)
      if (!empty_at(index(ix, ir))) {
        height[size_t(ix)] = ir + 1;
        break;
      }
  floor.assign(size_t(nx), kAxialEmptyFloor);
  for (int ix = 0; ix < nx; ++ix)
    for (int ir = 0; ir < nr; ++ir)
      if (!empty_at(index(ix, ir))) {
        floor[size_t(ix)] = ir;
        break;
      }
  global_max = nx > 0 ? *std::max_element(height.begin(), height.end()) : 0;
  // Max-tree: level 0 is h padded with zeros to a power of two; each level
  // halves the previous one, up to a single root.
  int padded = 1;
  while (padded < nx) padded *= 2;
  tree.assign(size_t(padded), 0);
  std::copy(height.begin(), height.end(), tree.begin());
  floor_tree.assign(size_t(padded), kAxialEmptyFloor);
  std::copy(floor.begin(), floor.end(), floor_tree.begin());
  level_offset = {0};
  for (int size = padded, at = 0; size > 1; size /= 2) {
    const int next = at + size;
    tree.resize(size_t(next + size / 2));
    floor_tree.resize(size_t(next + size / 2));
    for (int i = 0; i < size / 2; ++i) {
      tree[size_t(next + i)] = std::max(tree[size_t(at + 2 * i)], tree[size_t(at + 2 * i + 1)]);
      floor_tree[size_t(next + i)] = std::min(floor_tree[size_t(at + 2 * i)], floor_tree[size_t(at + 2 * i + 1)]);
    }
    level_offset.push_back(next);
    at = next;
  }
  if (level_offset.size() > size_t(kAxialMaxTreeLevels)) throw Error("axial map: too many columns for the max-tree");
  update_distance_map();
}

// The chessboard distance transform in two raster passes over the 8
// neighbours with unit steps, exact for the Chebyshev metric (Rosenfeld &
// Pfaltz 1966), linear in the texels.
void AxialMap::update_distance_map() {
  constexpr int kFar = kAxialMaxDistance;
  std::vector<int> d(count());
  for (size_t i = 0; i < count(); ++i) d[i] = empty_at(i) ? kFar : 0;
  auto relax = [&](int ix, int ir, int jx, int jr) {
    if (jx < 0 || jx >= nx || jr < 0 || jr >= nr) return;
    int& here = d[index(ix, ir)];
    here = std::min(here, d[index(jx, jr)] + 1);
  };
  for (int ir = 0; ir < nr; ++ir)
    for (int ix = 0; ix < nx; ++ix) {
      relax(ix, ir, ix - 1, ir);
      relax(ix, ir, ix - 1, ir - 1);
      relax(ix, ir, ix, ir - 1);
      relax(ix, ir, ix + 1, ir - 1);
    }
  for (int ir = nr - 1; ir >= 0; --ir)
    for (int ix = nx - 1; ix >= 0; --ix) {
      relax(ix, ir, ix + 1, ir);
      relax(ix, ir, ix + 1, ir + 1);
      relax(ix, ir, ix, ir + 1);
      relax(ix, ir, ix - 1, ir + 1);
    }
  distance.resize(count());
  for (size_t i = 0; i < count(); ++i) distance[i] = static_cast<uint8_t>(std::min(d[i], kFar));
}

AxialView AxialMap::view() const {
  AxialView v;
  v.nx = nx;
  v.nr = nr;
  v.texel = texel;
  v.origin = origin;
  v.axis = axis;
  v.tau_v = tau_v.data();
  for (size_t b = 0; b < emission.size() && b < size_t(kMaxBands); ++b) v.emission[b] = emission[b].data();
  v.height = height.data();
  v.floor = floor.data();
  v.tree = tree.data();
  v.floor_tree = floor_tree.data();
  v.n_levels = static_cast<int>(level_offset.size());
  for (int k = 0; k < v.n_levels; ++k) v.level_offset[k] = level_offset[size_t(k)];
  v.global_max = global_max;
  v.distance = distance.data();
  return v;
}

size_t AxialMap::bytes() const {
  size_t floats = tau_v.size();
  for (const auto& e : emission) floats += e.size();
  return floats * sizeof(float) + (height.size() + floor.size() + tree.size() + floor_tree.size()) * sizeof(int) +
         distance.size();
}

void check_axial_map(const AxialMap& map, const std::string& what) {
  if (map.nx < 1 || map.nr < 1) throw Error(what + ": the map needs at least 1 x 1 texels");
  if (map.nx > (1 << 24) || map.nr > (1 << 24)) throw Error(what + ": at most 2^24 texels per side");
  if (!(map.texel > 0.0f) || !std::isfinite(map.texel)) throw Error(what + ": texel size must be finite and > 0");
  const float n = length(map.axis);
  if (!(std::fabs(n - 1.0f) < 1e-5f)) throw Error(what + ": the axis direction must be a unit vector");
  if (!std::isfinite(map.origin.x) || !std::isfinite(map.origin.y) || !std::isfinite(map.origin.z))
    throw Error(what + ": the axis origin must be finite");
  if (map.tau_v.size() != map.count())
    throw Error(what + ": tau_v has " + std::to_string(map.tau_v.size()) + " values, the map " +
                std::to_string(map.count()));
  if (map.emission.size() > size_t(kMaxBands)) throw Error(what + ": at most 4 emission bands");
  auto check_values = [&](const std::vector<float>& v, const std::string& name) {
    if (v.size() != map.count())
      throw Error(what + ": " + name + " has " + std::to_string(v.size()) + " values, the map " +
                  std::to_string(map.count()));
    for (size_t i = 0; i < v.size(); ++i)
      if (!(std::isfinite(v[i]) && v[i] >= 0.0f))
        throw Error(what + ": " + name + " at (x=" + std::to_string(i % size_t(map.nx)) +
                    ", r=" + std::to_string(i / size_t(map.nx)) + ") is " + to_text(v[i]) +
                    "; must be finite and >= 0");
  };
  check_values(map.tau_v, "tau_v");
  for (size_t b = 0; b < map.emission.size(); ++b) check_values(map.emission[b], "emission " + std::to_string(b));
}

DensityGrid voxelize_axial_map(const AxialMap& map, float voxel, std::vector<std::vector<float>>* emission) {
  const Vec3 a = map.axis, end = map.origin + map.length() * a;
  const float R = map.radius();
  const float lo[3] = {std::fmin(map.origin.x, end.x) - R * std::sqrt(std::fmax(0.0f, 1 - a.x * a.x)),
                       std::fmin(map.origin.y, end.y) - R * std::sqrt(std::fmax(0.0f, 1 - a.y * a.y)),
                       std::fmin(map.origin.z, end.z) - R * std::sqrt(std::fmax(0.0f, 1 - a.z * a.z))};
  const float hi[3] = {std::fmax(map.origin.x, end.x) + R * std::sqrt(std::fmax(0.0f, 1 - a.x * a.x)),
                       std::fmax(map.origin.y, end.y) + R * std::sqrt(std::fmax(0.0f, 1 - a.y * a.y)),
                       std::fmax(map.origin.z, end.z) + R * std::sqrt(std::fmax(0.0f, 1 - a.z * a.z))};
  DensityGrid g;
  g.shape.voxel = voxel;
  g.shape.origin = {lo[0], lo[1], lo[2]};
  g.shape.nx = std::max(1, int(std::ceil((hi[0] - lo[0]) / voxel)));
  g.shape.ny = std::max(1, int(std::ceil((hi[1] - lo[1]) / voxel)));
  g.shape.nz = std::max(1, int(std::ceil((hi[2] - lo[2]) / voxel)));
  g.tau_v.assign(g.shape.count(), 0.0f);
  if (emission) emission->assign(map.emission.size(), std::vector<float>(g.shape.count(), 0.0f));
  const float rescale = voxel / map.texel;  // per texel edge -> per voxel edge
  for (int z = 0; z < g.shape.nz; ++z)
    for (int y = 0; y < g.shape.ny; ++y)
      for (int x = 0; x < g.shape.nx; ++x) {
        const Vec3 q = g.shape.centre(x, y, z) - map.origin;
        const float ax = dot(q, a), r = length(q - ax * a);
        const float fx = std::floor(ax / map.texel), fr = std::floor(r / map.texel);
        if (!(fx >= 0 && fx < map.nx && fr < map.nr)) continue;
        const size_t t = map.index(int(fx), int(fr)), v = g.shape.index(x, y, z);
        g.tau_v[v] = map.tau_v[t] * rescale;
        if (emission)
          for (size_t b = 0; b < map.emission.size(); ++b) (*emission)[b][v] = map.emission[b][t] * rescale;
      }
  return g;
}

const std::vector<std::string>& synthetic_axial_map_names() {
  static const std::vector<std::string> names{"bipolar", "lopsided", "shells", "empty", "full", "cloud"};
  return names;
}

AxialMap synthetic_axial_map(const std::string& name, int nx, int nr, float texel, int n_emission_bands,
                             float tau_scale) {
  const auto& names = synthetic_axial_map_names();
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw Error("axial map '" + name + "': not a synthetic map (known: bipolar, lopsided, shells, empty, full, cloud)");
  if (nx < 2 || nr < 2) throw Error("axial map '" + name + "': needs at least 2 x 2 texels");
  AxialMap m;
  m.nx = nx;
  m.nr = nr;
  m.texel = texel;
  m.tau_v.assign(m.count(), 0.0f);
  m.emission.assign(size_t(std::max(0, n_emission_bands)), std::vector<float>(m.count(), 0.0f));
  // Densities are tau_v per map radius: a texel holds value / nr.
  const float per_texel = tau_scale / float(nr);
  // Emission "colours" per band: bluish first band.
  const float colour[4] = {1.0f, 0.8f, 0.6f, 0.5f};
  const float aspect = float(nx) / float(nr);  // map length in radii
  // The bipolar lobes and the shells keep their size relative to the map's
  // length on maps shorter than 2 radii (a square map shows the same nebula
  // as a 2:1 one, with empty space above it, as a square image of a round
  // or thin nebula has); unchanged from 2:1 on.
  const float fit = std::min(0.5f * aspect, 1.0f);
  for (int ir = 0; ir < nr; ++ir)
    for (int ix = 0; ix < nx; ++ix) {
      const float u = (ix + 0.5f) / nx;  // 0..1 along the axis
      const float v = (ir + 0.5f) / nr;  // 0..1 from the axis out
      float tau = 0.0f, glow = 0.0f;
      if (name == "bipolar") {
        // Two thin-walled lobes meeting at a waist in the middle.
        const float s = std::fabs(2.0f * u - 1.0f);
        const float wall = 0.45f * fit * std::sin(kPi * std::min(s, 1.0f));
        if (s > 0.03f && s < 0.97f && std::fabs(v - wall) < 0.012f * fit) tau = 3.0f;
        if (s < 0.03f && v < 0.05f * fit) glow = 1.0f;  // a small emitting waist
      } else if (name == "lopsided") {
        // Calabash-like (OH 231.8+4.2): a dense core off the map's centre
        // with two unequal lobes along the axis, a long plume widening to one
        // side and a short stub to the other; nothing outside them, so most
        // texels are empty (docs/axial.md, "Maps", gives the fractions).
        const float u0 = 0.3f, a = (u - u0) * aspect, b = v;
        const float d2 = a * a / 0.015f + b * b / 0.03f;
        float rho = d2 < 1.0f ? 4.0f * (1.0f - 0.5f * d2) : 0.0f;
        if (u > u0 && u < 0.95f && b < 0.06f + 0.55f * (u - u0)) rho += 1.5f * std::exp(-(u - u0) * aspect / 0.8f);
        if (u < u0 && u > 0.1f && b < 0.05f + 0.7f * (u0 - u)) rho += 1.0f * std::exp(-(u0 - u) * aspect / 0.3f);
        tau = rho;
        if (d2 < 1.0f) glow = 2.0f;  // the core shines
      } else if (name == "shells") {
        // Three concentric spherical shells about the map's centre.
        const float a = (u - 0.5f) * aspect, rho = std::sqrt(a * a + v * v) / fit;
        for (float shell : {0.3f, 0.55f, 0.8f})
          if (std::fabs(rho - shell) < (shell < 0.5f ? 0.08f : 0.05f)) tau = 2.0f;
        if (std::fabs(rho - 0.3f) < 0.03f) glow = 1.0f;
      } else if (name == "cloud") {
        // The lopsided map before issue 15: a dense cloud off the map's
        // centre with a fainter tail to one side, no empty texel below its
        // height map (the validation scenes of docs/diffuse.md use it).
        const float a = (u - 0.32f) * aspect, b = v;
        const float d2 = a * a / 0.08f + b * b / 0.25f;
        const float tail = (u > 0.32f) ? std::exp(-((u - 0.32f) * aspect) / 0.6f) * std::exp(-b * b / 0.05f) : 0.0f;
        const float rho = 4.0f * std::exp(-d2) + 1.5f * tail;
        if (rho > 0.02f) tau = rho;
        if (d2 < 0.15f) glow = 2.0f;
      } else if (name == "full") {
        tau = 0.5f + 0.5f * u;
        glow = 0.2f;
      }
      const size_t i = m.index(ix, ir);
      m.tau_v[i] = tau * per_texel;
      for (size_t b = 0; b < m.emission.size(); ++b) m.emission[b][i] = glow * colour[b] * per_texel;
    }
  m.update_skip_structures();
  return m;
}

}  // namespace nebula
