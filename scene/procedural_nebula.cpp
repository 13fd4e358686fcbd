// The built-in reflection nebula (docs/scene.md, "Procedural density").
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/philox.h"
#include "scene/density_sources.h"
#include "scene/scene_checks.h"

namespace nebula {
namespace {

using scene_detail::finite;
using scene_detail::vec_text;

// Collects the first issue; later checks are skipped once one is found.
struct Checker {
  std::optional<ParameterIssue> issue;

  void refuse(const char* name, const std::string& value, const std::string& reason) {
    if (!issue) issue = ParameterIssue{name, "is " + value + "; " + reason};
  }
  void range(const char* name, double v, double lo, double hi, bool lo_open, bool hi_open) {
    const bool ok =
        std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (!ok)
      refuse(name, to_text(v),
             std::string("must be in ") + (lo_open ? "(" : "[") + to_text(lo) + ", " + to_text(hi) +
                 (hi_open ? ")" : "]"));
  }
  void direction(const char* name, Vec3 v) {
    if (!finite(v) || !(length(v) > 1e-6f))
      refuse(name, vec_text(v), "must be a finite, non-zero direction");
  }
};

struct Vec3d {
  double x, y, z;
};
Vec3d unit(Vec3 v) {
  const double l = std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
  return {v.x / l, v.y / l, v.z / l};
}

// Largest cycles per cube edge the noise lattice may have: bounds its memory.
constexpr double kMaxNoiseFrequency = 65536.0;

// Lattice value of octave `octave` at integer point (i, j, k): Philox4x32-10
// of the point and octave, keyed by the seed, mapped to (2m + 1) 2^-23 - 1
// with m the top 23 bits: exact in float, symmetric in (-1, 1).
float lattice_value(uint64_t seed, uint32_t octave, uint32_t i, uint32_t j, uint32_t k) {
  const U32x4 r = philox4x32_10(U32x4{i, j, k, octave}, static_cast<uint32_t>(seed),
                                static_cast<uint32_t>(seed >> 32));
  return static_cast<float>((2.0 * double(r.v0 >> 9) + 1.0) * 0x1p-23 - 1.0);
}

// Quintic fade 6t^5 - 15t^4 + 10t^3: C2-continuous interpolation weights.
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

struct Octave {
  double frequency, weight;
  uint32_t index;
};

struct NoisePlan {
  std::vector<Octave> octaves;  // those at or below n / 2 cycles per edge
  double normalisation = 1;     // sum of the weights of all requested octaves
};

NoisePlan plan_noise(const ProceduralParams& p) {
  NoisePlan plan;
  double total = 0, f = p.noise_frequency, w = 1;
  for (int o = 0; o < p.noise_octaves; ++o) {
    total += w;
    if (f <= 0.5 * p.n) plan.octaves.push_back({f, w, uint32_t(o)});
    f *= p.noise_lacunarity;
    w *= p.noise_gain;
  }
  plan.normalisation = total > 0 ? total : 1;
  return plan;
}

// Trilinear interpolation of lattice values with faded weights; `value(i, j, k)`
// supplies the lattice.
template <class Lattice>
double value_noise(double f, double u, double v, double w, const Lattice& value) {
  const double px = u * f, py = v * f, pz = w * f;
  const double fx = std::floor(px), fy = std::floor(py), fz = std::floor(pz);
  const uint32_t i = uint32_t(fx), j = uint32_t(fy), k = uint32_t(fz);
  const double tx = fade(px - fx), ty = fade(py - fy), tz = fade(pz - fz);
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double x00 = lerp(value(i, j, k), value(i + 1, j, k), tx);
  const double x10 = lerp(value(i, j + 1, k), value(i + 1, j + 1, k), tx);
  const double x01 = lerp(value(i, j, k + 1), value(i + 1, j, k + 1), tx);
  const double x11 = lerp(value(i, j + 1, k + 1), value(i + 1, j + 1, k + 1), tx);
  return lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz);
}

// One octave's lattice, precomputed over the unit cube: points 0..floor(f)+1.
struct LatticeCache {
  uint32_t side = 0;
  std::vector<float> values;
  float operator()(uint32_t i, uint32_t j, uint32_t k) const {
    return values[(size_t(k) * side + j) * side + i];
  }
};

LatticeCache cache_octave(uint64_t seed, const Octave& octave) {
  LatticeCache cache;
  cache.side = uint32_t(std::floor(octave.frequency)) + 2;
  const uint32_t s = cache.side;
  cache.values.resize(size_t(s) * s * s);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, s), [&](const auto& ks) {
    for (uint32_t k = ks.begin(); k != ks.end(); ++k)
      for (uint32_t j = 0; j < s; ++j)
        for (uint32_t i = 0; i < s; ++i)
          cache.values[(size_t(k) * s + j) * s + i] = lattice_value(seed, octave.index, i, j, k);
  });
  return cache;
}

}  // namespace

std::optional<ParameterIssue> check_procedural(const ProceduralParams& p) {
  Checker c;
  if (p.n < 2) c.refuse("n", std::to_string(p.n), "must be at least 2 voxels per edge");
  if (!c.issue) {
    try {
      check_grid_size("a cube of n = " + std::to_string(p.n), uint64_t(p.n), uint64_t(p.n),
                      uint64_t(p.n));
    } catch (const Error& e) {
      c.refuse("n", std::to_string(p.n), e.what());
    }
  }
  c.range("size_pc", p.size_pc, 0, 1e9, true, false);
  if (!finite(p.origin_pc) || std::fabs(p.origin_pc.x) > 1e30f ||
      std::fabs(p.origin_pc.y) > 1e30f || std::fabs(p.origin_pc.z) > 1e30f)
    c.refuse("origin_pc", vec_text(p.origin_pc), "must be finite");
  if (!finite(p.star) || p.star.x < 0 || p.star.x > 1 || p.star.y < 0 || p.star.y > 1 ||
      p.star.z < 0 || p.star.z > 1)
    c.refuse("star", vec_text(p.star), "must lie in the cube: each fraction of the edge in [0, 1]");
  c.direction("wind_direction", p.wind_direction);
  c.direction("near_side", p.near_side);
  c.range("bubble_radius", p.bubble_radius, 0, 2, true, false);
  c.range("bubble_offset", p.bubble_offset, 0, 2, false, false);
  if (!(p.bubble_offset < p.bubble_radius))
    c.refuse("bubble_offset", to_text(p.bubble_offset),
             "must be less than bubble_radius = " + to_text(p.bubble_radius) +
                 " (the star lies inside its bubble)");
  c.range("bubble_tau", p.bubble_tau, 0, 1e30, false, false);
  c.range("shell_thickness", p.shell_thickness, 0, 2, true, false);
  c.range("shell_tau", p.shell_tau, 0, 1e30, false, false);
  c.range("cloud_tau", p.cloud_tau, 0, 1e30, false, false);
  c.range("scale_length", p.scale_length, 0, 1e6, true, false);
  c.range("far_multiplier", p.far_multiplier, 0, 1e6, true, false);
  c.range("far_transition", p.far_transition, 0, 2, false, false);
  c.range("noise_amplitude", p.noise_amplitude, 0, 20, false, false);
  c.range("noise_frequency", p.noise_frequency, 0, kMaxNoiseFrequency, true, false);
  if (p.noise_octaves < 0 || p.noise_octaves > 16)
    c.refuse("noise_octaves", std::to_string(p.noise_octaves), "must be in [0, 16]");
  c.range("noise_gain", p.noise_gain, 0, 1, true, false);
  c.range("noise_lacunarity", p.noise_lacunarity, 1, 16, true, false);
  c.range("far_offset", p.far_offset, -2, 2, false, false);
  c.range("far_warp", p.far_warp, 0, 2, false, false);
  c.range("filament_amplitude", p.filament_amplitude, 0, 20, false, false);
  c.range("filament_frequency", p.filament_frequency, 0, 4096, true, false);
  if (p.filament_octaves < 1 || p.filament_octaves > 8)
    c.refuse("filament_octaves", std::to_string(p.filament_octaves), "must be in [1, 8]");
  c.range("filament_sharpness", p.filament_sharpness, 0, 64, true, false);
  c.range("edge_fade", p.edge_fade, 0, 0.5, false, false);
  if (!c.issue && p.noise_octaves > 0) {
    const double top = p.noise_frequency * std::pow(p.noise_lacunarity, p.noise_octaves - 1);
    if (!(top <= kMaxNoiseFrequency))
      c.refuse("noise_octaves", std::to_string(p.noise_octaves),
               "the highest octave would have " + to_text(top) + " cycles per edge, more than " +
                   to_text(kMaxNoiseFrequency));
  }
  return c.issue;
}

void validate_procedural(const ProceduralParams& p) {
  if (const auto issue = check_procedural(p)) throw Error(issue->parameter + ": " + issue->reason);
}

Vec3 procedural_star_position(const ProceduralParams& p) {
  const float s = static_cast<float>(p.size_pc);
  return p.origin_pc + Vec3{s * p.star.x, s * p.star.y, s * p.star.z};
}

double procedural_noise(const ProceduralParams& p, double u, double v, double w) {
  const NoisePlan plan = plan_noise(p);
  double sum = 0;
  for (const Octave& o : plan.octaves)
    sum += o.weight * value_noise(o.frequency, u, v, w, [&](uint32_t i, uint32_t j, uint32_t k) {
             return double(lattice_value(p.seed, o.index, i, j, k));
           });
  return sum / plan.normalisation;
}

DensityGrid procedural_nebula(const ProceduralParams& p) {
  validate_procedural(p);
  const int n = p.n;
  DensityGrid grid;
  grid.shape.nx = grid.shape.ny = grid.shape.nz = n;
  grid.shape.origin = p.origin_pc;
  grid.shape.voxel = static_cast<float>(p.size_pc / n);
  grid.tau_v.resize(grid.shape.count());

  const NoisePlan plan = plan_noise(p);
  std::vector<LatticeCache> lattices;
  if (p.noise_amplitude > 0 || p.far_warp > 0)
    for (const Octave& o : plan.octaves) lattices.push_back(cache_octave(p.seed, o));
  // Filaments: lattices of their own (octave indices from 64 on), up to n / 2 cycles per edge.
  std::vector<Octave> ridge_octaves;
  std::vector<LatticeCache> ridges;
  double ridge_total = 0;
  if (p.filament_amplitude > 0) {
    double f = p.filament_frequency, w = 1;
    for (int o = 0; o < p.filament_octaves; ++o, f *= 2, w *= 0.5) {
      ridge_total += w;
      if (f <= 0.5 * p.n) ridge_octaves.push_back({f, w, uint32_t(64 + o)});
    }
    for (const Octave& o : ridge_octaves) ridges.push_back(cache_octave(p.seed, o));
  }

  const Vec3d wind = unit(p.wind_direction), near = unit(p.near_side);
  const double sx = p.star.x, sy = p.star.y, sz = p.star.z;
  const double cx = sx + p.bubble_offset * wind.x, cy = sy + p.bubble_offset * wind.y,
               cz = sz + p.bubble_offset * wind.z;
  const double shell_centre = p.bubble_radius + 0.5 * p.shell_thickness;
  const double shell_k = 4.0 * std::log(2.0) / (p.shell_thickness * p.shell_thickness);  // FWHM
  const double per_voxel = 1.0 / n;

  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const auto& zs) {
    for (int z = zs.begin(); z != zs.end(); ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const double u = (x + 0.5) / n, v = (y + 0.5) / n, w = (z + 0.5) / n;
          const double dx = u - cx, dy = v - cy, dz = w - cz;
          const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
          const double base =
              d < p.bubble_radius ? p.bubble_tau
                                  : p.cloud_tau * std::exp(-(d - p.bubble_radius) / p.scale_length);
          const double s = d - shell_centre;
          const double shell = p.shell_tau * std::exp(-shell_k * s * s);
          double noise = 0;  // the fractal noise in [-1, 1]
          if (!lattices.empty()) {
            double sum = 0;
            for (size_t o = 0; o < lattices.size(); ++o)
              sum += plan.octaves[o].weight *
                     value_noise(plan.octaves[o].frequency, u, v, w, lattices[o]);
            noise = sum / plan.normalisation;
          }
          // Height towards the camera side, measured from the far side's boundary
          // (the star's plane unless moved back and warped).
          const double h = (u - sx) * near.x + (v - sy) * near.y + (w - sz) * near.z + p.far_offset +
                           p.far_warp * noise;
          double far = 1;
          if (p.far_transition > 0) {
            const double t = std::fmin(std::fmax(-h / p.far_transition, 0.0), 1.0);
            far = 1 + (p.far_multiplier - 1) * t * t * (3 - 2 * t);
          } else if (h < 0) {
            far = p.far_multiplier;
          }
          double contrast = p.noise_amplitude > 0 ? std::exp(p.noise_amplitude * noise) : 1.0;
          if (!ridges.empty()) {
            double ridge = 0;
            for (size_t o = 0; o < ridges.size(); ++o)
              ridge += ridge_octaves[o].weight *
                       std::pow(1.0 - std::fabs(value_noise(ridge_octaves[o].frequency, u, v, w, ridges[o])),
                                p.filament_sharpness);
            contrast *= std::exp(p.filament_amplitude * (ridge / ridge_total - 0.5));
          }
          double fade_out = 1;  // no hard cube faces: smoothstep to 0 at each face
          if (p.edge_fade > 0)
            for (double c : {u, v, w}) {
              const double t = std::fmin(std::fmin(c, 1.0 - c) / p.edge_fade, 1.0);
              fade_out *= t * t * (3 - 2 * t);
            }
          grid.tau_v[grid.shape.index(x, y, z)] =
              static_cast<float>((base + shell) * far * contrast * fade_out * per_voxel);
        }
  });
  check_grid_values("procedural density", grid.shape, grid.tau_v);
  return grid;
}

}  // namespace nebula
