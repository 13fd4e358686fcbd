#pragma once
// The reference ray marcher (DESIGN.md section 3, "Ray marching"): exact,
// step-free voxel traversal; a voxel crossed over a chord c adds radiance
// T_in (sum_s E_s P(tau_sct, theta_s) + j) c / l, then T *= exp(-tau_b c / l).
// Written once for host and device.
#include <cstdint>

#include "core/bands.h"
#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "diffuse/diffuse_field.h"
#include "diffuse/zonal_light.h"
#include "illumination/chord_irradiance.h"
#include "illumination/optical_depth_bake.h"
#include "tables/chord_phase.h"
#include "tables/table_lookup.h"

namespace nebula {

// One star as a marcher sees it (this one and the axial one): band powers and
// its baked V-band depth to every cell's sphere (voxel or texel).
struct StarView {
  Vec3 position;
  float power[kMaxBands];  // band luminosity, L_sun
  const float* depth_v;    // [cell]
};

// Everything a ray needs, by value (pointers to host or device memory).
struct MarchScene {
  DensityView density;
  int n_bands = 0;
  float extinction_ratio[kMaxBands];  // A_b / A_V
  float albedo[kMaxBands];
  TableView table[kMaxBands];         // P per band; unused where albedo is 0
  const float* emission[kMaxBands];   // j per voxel and band, or null
  const StarView* stars = nullptr;
  int n_stars = 0;
  float min_transmittance = 1e-4f;    // rays stop once every band is below this
  RayFootprint footprint;             // the camera's pixel width along a ray (starlight near a star)
  bool has_diffuse = false;           // light scattered between voxels (diffuse/), per band where baked
  DiffuseView diffuse;
  // The field's light each voxel scatters towards this view's eye, per band
  // (null where the band has no field): raycast/diffuse_light.h fills it
  // before the march.
  const float* diffuse_light[kMaxBands] = {};
  // Its forward peak per voxel and band, filled with it: the exact traversal
  // reads it instead of looking the response up at every crossing.
  const float* diffuse_peak[kMaxBands] = {};
  // The preview (MarchMode::voxel_sources): all the light each voxel sends
  // towards this view's eye, per band, filled before the march by
  // raycast/voxel_sources.h; the march then only carries it to the eye.
  const float* voxel_source[kMaxBands] = {};
  // Rays passing farther than this from every star take the star's phase at
  // each chord's half-light point (passes_near_a_star; NearStarRadius, by the
  // ray's direction).
  NearStarRadius near_star_radius;
  // Near rays' chords within this of a zonal star take the field's light on
  // the chord (add_chord_field_light), the others the per-view pass's:
  // kChordFieldVoxels voxels (march_scene.h).
  float chord_field_radius = 0.0f;
};

// How far from a zonal star (in voxels) near rays evaluate the field on their
// chords. On a sphere of radial depth 5 at g = 0.9, a = 0.9 (32^3 voxels, CPU)
// the L2 error beyond the truth's noise was 0.113 with none, 0.107, 0.097,
// 0.081 and 0.055 with 2, 4, 8 and 16 voxels, and 0.055 with every chord;
// 16 voxels cost the 1080p frame at 256^3 0.15 ms (H200; docs/diffuse.md).
constexpr float kChordFieldVoxels = 16.0f;

struct RayResult {
  float radiance[kMaxBands];
  float transmittance[kMaxBands];
  int table_clamps;
};

// One ray's radiance times the exposure, stored at pixel (x, y) of an image of
// n_bands planes of width x height ([band][y][x], host or device memory): the
// pixel write of every marcher's CPU loop and CUDA kernel.
NEBULA_HD void store_radiance(const RayResult& r, int n_bands, float exposure, float* pixels, int width, int height,
                              int x, int y) {
  const size_t plane = size_t(width) * height;
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < n_bands) pixels[b * plane + size_t(y) * width + x] = exposure * r.radiance[b];
}

// One star's light that dust of V-band depth tau_v per cell sends towards the
// eye per band, per unit of chord / edge, added to `source`: E P(tau_sct,
// theta), with E from the star's mean 1 / r^2 over the cell's chord and theta
// at the chord's point `at` (illumination/chord_irradiance.h), or with
// kChordPhase P averaged over the chord's angles where they span enough bins
// (chord_phase_mean). depth_v is the star's baked V-band depth to the cell.
// Shared by the 3D marcher and the axial one (Scene: n_bands,
// extinction_ratio, albedo, table).
template <bool kChordPhase = false, class Scene>
NEBULA_HD void add_star_light(const Scene& s, Vec3 star, const float* power, float depth_v, const ChordIrradiance& at,
                              float tau_v, Vec3 to_eye, float* source, int* clamps) {
  const Vec3 d = at.point - star;
  const float r2 = dot(d, d);
  // theta: between the light's direction (star to dust) and the way to the eye;
  // one reciprocal square root, no division (docs/performance.md, "Axial maps").
  const float mu = r2 > 0.0f ? dot(d, to_eye) * reciprocal_sqrt(r2) : 0.0f;  // the bins clamp it to [-1, 1]
  TableView::AngleCell u;  // the angle's bin cell, shared by bands with equal binning
  int u_from = -1;
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b) {
    if (b >= s.n_bands) break;
    if (!(s.albedo[b] > 0.0f)) continue;
    const float tau_b = tau_v * s.extinction_ratio[b];
    const float e = power[b] * kInv4Pi * at.inv_r2 * fast_exp(-depth_v * s.extinction_ratio[b]);
    if constexpr (kChordPhase) {
      if (chord_takes_phase_mean(s.table[b], at.a0, at.a1)) {
        source[b] += e * chord_phase_mean(s.table[b], s.albedo[b] * tau_b, at.a0, at.a1, clamps);
        continue;
      }
    }
    if (u_from < 0 || s.table[b].bins.kind != s.table[u_from].bins.kind ||
        s.table[b].bins.n != s.table[u_from].bins.n) {
      u = s.table[b].angle_cell(s.table[b].angle_coordinate(mu));
      u_from = b;
    }
    source[b] += e * s.table[b].lookup_at(s.albedo[b] * tau_b, u, clamps);
  }
}

// Light that dust of V-band depth per voxel edge tau_v sends towards the eye
// per band, per unit of chord / l: sum over stars of E_s P(tau_sct, theta_s).
// irradiance_of(k) is star k's ChordIrradiance over the chord (or at the
// sample), depth_of(k) its baked V-band depth to the voxel.
template <bool kChordPhase = false, class IrradianceOf, class DepthOf>
NEBULA_HD void scattered_source(const MarchScene& s, float tau_v, Vec3 to_eye, IrradianceOf&& irradiance_of,
                                DepthOf&& depth_of, float* source, int* clamps) {
  if (!(tau_v > 0.0f)) return;
  for (int k = 0; k < s.n_stars; ++k)
    add_star_light<kChordPhase>(s, s.stars[k].position, s.stars[k].power, depth_of(k), irradiance_of(k), tau_v,
                                to_eye, source, clamps);
}

// Whether a ray passes within s.near_star_radius of a star (tables/chord_phase.h).
NEBULA_HD bool passes_near_a_star(const MarchScene& s, Vec3 origin, Vec3 dir) {
  return passes_near_a_star(s.stars, s.n_stars, s.near_star_radius, s.footprint, origin, dir);
}

// Whether p lies within `radius` of a star with zonal degrees.
NEBULA_HD bool near_a_zonal_star(const DiffuseView& f, Vec3 p, float radius) {
  for (int k = 0; k < f.zonal_stars; ++k) {
    const Vec3 d = p - f.zonal_star[k];
    if (dot(d, d) < radius * radius) return true;
  }
  return false;
}

// The diffuse field's light and forward peak on a near ray's chord in voxel
// (x, y, z) of depth tau_v, evaluated at the chord's middle `mid` for the
// ray's own direction to the eye, added to source and written to peak. With
// zonal degrees the light a voxel scatters towards the eye depends on the
// angle between the eye and the direction from the star, which near the star
// turns by tens of degrees across one voxel while the zonal degrees resolve a
// few: the per-view pass's value at the voxel's centre then stands for rays it
// does not fit (on a star seen through radial depth 5 at g = 0.9 the four
// pixels at the star were 0.865 of the truth with it, 0.954 with this).
// Inline: out of line (__noinline__) the call cost the near rays' kernel 0.48
// ms of a 1080p frame at 256^3 even where no chord took it (H200).
NEBULA_HD void add_chord_field_light(const MarchScene& s, int x, int y, int z, Vec3 mid, Vec3 to_eye, float tau_v,
                                     float* source, float* peak) {
  float light[kMaxBands] = {}, chord_peak[kMaxBands] = {};
  field_scattered_light<kMaxDiffuseDegree, true>(s, s.diffuse, tau_v, s.diffuse.cell_of(x, y, z), mid, to_eye, light,
                                                 chord_peak, /*clamp=*/true, s.diffuse.degree);
  for (int b = 0; b < s.n_bands; ++b)
    if (s.diffuse_light[b]) {
      source[b] += light[b];
      peak[b] = chord_peak[b];
    }
}

// A cell-centred field at `pos`: trilinear (clamped at the grid's edge) or
// the value of the voxel holding pos.
NEBULA_HD float sample_field(const GridShape& g, const float* f, Vec3 pos, bool trilinear) {
  const float u[3] = {(pos.x - g.origin.x) / g.voxel, (pos.y - g.origin.y) / g.voxel,
                      (pos.z - g.origin.z) / g.voxel};
  const int n[3] = {g.nx, g.ny, g.nz};
  if (!trilinear) {
    int c[3];
    for (int k = 0; k < 3; ++k) {
      c[k] = static_cast<int>(floorf(u[k]));
      c[k] = c[k] < 0 ? 0 : (c[k] >= n[k] ? n[k] - 1 : c[k]);
    }
    return f[g.index(c[0], c[1], c[2])];
  }
  int i0[3], i1[3];
  float w[3];
  for (int k = 0; k < 3; ++k) {
    const float x = clamp(u[k] - 0.5f, 0.0f, float(n[k] - 1));
    i0[k] = static_cast<int>(x);
    i1[k] = i0[k] + 1 < n[k] ? i0[k] + 1 : i0[k];
    w[k] = x - i0[k];
  }
  float v = 0.0f;
  for (int corner = 0; corner < 8; ++corner) {
    const int x = corner & 1 ? i1[0] : i0[0], y = corner & 2 ? i1[1] : i0[1], z = corner & 4 ? i1[2] : i0[2];
    const float weight = (corner & 1 ? w[0] : 1 - w[0]) * (corner & 2 ? w[1] : 1 - w[1]) * (corner & 4 ? w[2] : 1 - w[2]);
    v += weight * f[g.index(x, y, z)];
  }
  return v;
}

// How a ray gathers light: the exact traversal (the reference), or the smooth
// display mode sampling the fields at a fixed step (in voxels) along the ray.
struct MarchMode {
  float step_voxels = 0.0f;  // 0: exact traversal
  bool trilinear = true;     // smooth mode: trilinear fields, else the voxel's value
  // The interactive preview: the exact traversal, but each voxel's light
  // towards the eye taken once per view at the voxel's centre
  // (raycast/voxel_sources.h) instead of over every ray's chord. Overrides
  // step_voxels. Its error against the exact frame: docs/marcher.md.
  bool voxel_sources = false;
};

// Marches from `origin` along unit `dir` through the whole grid. In both
// modes a voxel's dust is seen through the transmittance to where the ray
// enters that voxel (DESIGN.md: P holds the voxel's own extinction, so a
// sub-voxel step must not darken its voxel again); the smooth mode spreads
// the voxel's chord over samples of the interpolated fields inside it.
// kDiffuse: the scene has a diffuse field, its light per voxel already
// evaluated for this view (raycast/diffuse_light.h): it adds to the voxel's
// source as emission does, and its forward peak to the voxel's transmittance
// (the exact traversal and the preview read the peak evaluated with the
// light; the smooth mode looks it up per sample). kVoxelSources: the preview, each voxel's
// light read from s.voxel_source (exact traversal only). kZonal: the field
// has zonal degrees (the looked-up peak blends towards the zonal response,
// DiffuseView::zonal_weight); without them the kernel carries none of that code. kChordPhase: the star's phase
// averaged over a chord's angles near the star (the exact traversal; the
// rays that need it are those passes_near_a_star picks. The smooth mode with
// voxel values always averages, over the voxel's chord).
template <bool kSmooth, bool kDiffuse, bool kVoxelSources = false, bool kZonal = false, bool kChordPhase = false>
NEBULA_HD RayResult march_ray(const MarchScene& s, Vec3 origin, Vec3 dir, MarchMode mode) {
  static_assert(!(kSmooth && kVoxelSources), "the preview's voxel sources go with the exact traversal");
  static_assert(kDiffuse || !kZonal, "zonal degrees belong to a diffuse field");
  static_assert(!kChordPhase || !(kSmooth || kVoxelSources), "the chord's angles belong to the exact traversal");
  RayResult out{};
  for (int b = 0; b < kMaxBands; ++b) out.transmittance[b] = 1.0f;
  const GridShape& g = s.density.shape;
  // A far point beyond the grid; traverse_segment clips to the grid box.
  const Vec3 span = g.upper() - g.origin;
  const Vec3 mid = g.origin + 0.5f * span;
  const float far = length(origin - mid) + length(span) + g.voxel;
  float t_enter = 0.0f, t_exit = 0.0f;
  if (!clip_to_grid(g, origin, dir, far, t_enter, t_exit)) return out;
  const float inv_voxel = 1.0f / g.voxel;
  const float step = mode.step_voxels * g.voxel;
  const Vec3 to_eye = -dir;
  // The zonal response's weight at p (0 without zonal degrees, at compile time).
  auto zonal_weight = [&](Vec3 p) { return kZonal ? s.diffuse.zonal_weight(p, to_eye) : 0.0f; };
  float t = t_enter;  // where the current voxel begins along the ray
  // The walk's state in arrays: this kernel is held to 64 registers (core/dda.h).
  traverse_segment_cells<WalkState::Arrays>(g, origin, origin + far * dir,
                                            [&](int x, int y, int z, size_t cell, float chord) -> bool {
    const float tau_v = s.density.tau_v[cell];
    float source[kMaxBands] = {};
    float peak[kMaxBands] = {};  // the diffuse response's forward peak (kDiffuse)
    if constexpr (kSmooth) {
      // Samples at t_enter + (k + 1/2) step that fall inside this voxel.
      const float first = ceilf((t - t_enter) / step - 0.5f);
      for (float k = fmaxf(first, 0.0f);; k += 1.0f) {
        const float ts = t_enter + (k + 0.5f) * step;
        if (ts >= t + chord || ts >= t_exit) break;
        // Trilinear fields are smooth, so is their geometry; voxel values keep
        // the chord's geometry (its starlight over the chord, the phase
        // averaged over its angles near a star), as the exact traversal does.
        const Vec3 pos = mode.trilinear ? origin + ts * dir : origin + (t + 0.5f * chord) * dir;
        float local[kMaxBands] = {};
        for (int b = 0; b < s.n_bands; ++b)
          local[b] = s.emission[b] ? sample_field(g, s.emission[b], pos, mode.trilinear) : 0.0f;
        const float tau_sample = sample_field(g, s.density.tau_v, pos, mode.trilinear);
        scattered_source</*kChordPhase=*/true>(  // (a point's irradiance has no angle span)
            s, tau_sample, to_eye,
            [&](int k_star) {
              const Vec3 star = s.stars[k_star].position;
              return mode.trilinear ? point_irradiance(pos, star, s.footprint.width(ts))
                                    : chord_irradiance(origin, dir, t, t + chord, star, s.footprint);
            },
            [&](int k_star) { return sample_field(g, s.stars[k_star].depth_v, pos, mode.trilinear); }, local,
            &out.table_clamps);
        if constexpr (kDiffuse) {
          if (tau_sample > 0.0f)
            for (int b = 0; b < s.n_bands; ++b)
              if (s.diffuse_light[b]) {
                local[b] += sample_field(g, s.diffuse_light[b], pos, mode.trilinear);
                peak[b] += s.diffuse.peak(b, s.albedo[b] * tau_sample * s.extinction_ratio[b],
                                          zonal_weight(pos)) *
                           step / fmaxf(chord, 1e-30f);
              }
        }
        for (int b = 0; b < s.n_bands; ++b) source[b] += local[b] * step / fmaxf(chord, 1e-30f);
      }
    } else if constexpr (kVoxelSources) {
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b)
        if (b < s.n_bands) source[b] = s.voxel_source[b][cell];
      if constexpr (kDiffuse) {
        // The field's forward peak, evaluated with the voxel's source.
        if (tau_v > 0.0f) {
          NEBULA_UNROLL
          for (int b = 0; b < kMaxBands; ++b)
            if (b < s.n_bands && s.diffuse_peak[b]) peak[b] = s.diffuse_peak[b][cell];
        }
      }
    } else {
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b)
        if (b < s.n_bands) source[b] = s.emission[b] ? s.emission[b][cell] : 0.0f;
      if (tau_v > 0.0f && s.n_stars > 0) {
        scattered_source<kChordPhase>(
            s, tau_v, to_eye,
            [&](int k_star) {
              return chord_irradiance<kChordPhase>(origin, dir, t, t + chord, s.stars[k_star].position, s.footprint);
            },
            [&](int k_star) { return s.stars[k_star].depth_v[cell]; }, source, &out.table_clamps);
      }
      if constexpr (kDiffuse) {
        // The voxel's light and forward peak for this view (the peak blended
        // with the zonal response's as the light is; raycast/diffuse_light.h).
        if (tau_v > 0.0f) {
          bool on_chord = false;
          if constexpr (kChordPhase && kZonal) {
            // Near a star, the zonal response where the ray crosses the voxel.
            const Vec3 mid = origin + (t + 0.5f * chord) * dir;
            on_chord = near_a_zonal_star(s.diffuse, mid, s.chord_field_radius);
            if (on_chord) add_chord_field_light(s, x, y, z, mid, to_eye, tau_v, source, peak);
          }
          if (!on_chord) {
            NEBULA_UNROLL
            for (int b = 0; b < kMaxBands; ++b)
              if (b < s.n_bands && s.diffuse_light[b]) {
                source[b] += s.diffuse_light[b][cell];
                peak[b] = s.diffuse_peak[b][cell];
              }
          }
        }
      }
    }
    t += chord;
    const float fraction = chord * inv_voxel;
    bool visible = false;
    NEBULA_UNROLL
    for (int b = 0; b < kMaxBands; ++b) {
      if (b >= s.n_bands) break;
      out.radiance[b] += out.transmittance[b] * source[b] * fraction;
      if constexpr (kDiffuse)
        out.transmittance[b] *= fminf(1.0f, expf(-tau_v * s.extinction_ratio[b] * fraction) + peak[b] * fraction);
      else
        out.transmittance[b] *= expf(-tau_v * s.extinction_ratio[b] * fraction);
      visible = visible || out.transmittance[b] >= s.min_transmittance;
    }
    return visible;
  });
  return out;
}

// Calls f(std::true_type) when the scene's field has zonal degrees, else
// f(std::false_type): the one place that makes it a template argument.
template <class F>
decltype(auto) dispatch_zonal(const MarchScene& s, F&& f) {
  if (s.has_diffuse && s.diffuse.zonal > 0) return f(std::true_type{});
  return f(std::false_type{});
}

// Calls f(smooth, diffuse, voxel_sources, zonal) with std::bool_constant values: the one place
// that turns the scene's mode into march_ray's template arguments, for the CPU loop
// and the CUDA launch. The exact traversal, the smooth mode and the diffuse
// field's terms (with or without zonal degrees) are compiled apart, so the
// reference path carries none of the others' code (registers, branches). The
// preview's voxel sources go with the exact traversal.
template <class F>
decltype(auto) dispatch_march(const MarchScene& s, MarchMode mode, F&& f) {
  auto with_smooth = [&](auto diffuse, auto zonal) -> decltype(auto) {
    if (mode.voxel_sources) return f(std::false_type{}, diffuse, std::true_type{}, zonal);
    return mode.step_voxels > 0.0f ? f(std::true_type{}, diffuse, std::false_type{}, zonal)
                                   : f(std::false_type{}, diffuse, std::false_type{}, zonal);
  };
  if (!s.has_diffuse) return with_smooth(std::false_type{}, std::false_type{});
  return dispatch_zonal(s, [&](auto zonal) -> decltype(auto) { return with_smooth(std::true_type{}, zonal); });
}

}  // namespace nebula
