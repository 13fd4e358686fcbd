#pragma once
// The mean of a table's P over the scattering angles a voxel's chord sees a
// star under: the marchers' near-star phase (raycast/ray_march.h and
// spectral/spectral_march.h; docs/marcher.md, "The phase over the chord's
// angles").
#include "core/camera.h"
#include "core/hd.h"
#include "core/math.h"
#include "tables/table_lookup.h"

namespace nebula {

// Near a star a chord sees it under a wide range of angles: with 1 / r^2
// the chord's light is spread evenly over a = atan(s / b) in [a0, a1]
// (ChordIrradiance), and the scattering angle towards the eye is
// theta = pi/2 + a, so the chord scatters the mean of P over those angles.
// The half-light point takes P at their middle only (the midpoint rule): a
// chord through the star at 90 degrees, which put the star's own pixels of a
// uniform sphere (g = 0.6) at 0.74 of the truth (docs/marcher.md, "Star
// light over a cell's chord"). Spans of kChordPhaseMinBins or more of a
// uniform-theta table's bins take the mean of its interpolant over them
// (TableView::mean_over_angles); shorter spans, and uniform-mu tables (whose
// bins are not uniform in the angle), keep the midpoint.
constexpr float kChordPhaseMinBins = 2.0f;

// Whether a chord seeing the star over [a0, a1] takes the mean of `table`'s
// P over those angles.
NEBULA_HD bool chord_takes_phase_mean(const TableView& table, float a0, float a1) {
  return table.bins.kind == AngularBinning::UniformTheta &&
         (a1 - a0) * float(table.n_mu) * (1.0f / kPi) >= kChordPhaseMinBins;
}

// The mean of P(tau_sct, theta) over theta = pi/2 + a, a in [a0, a1], for
// uniform-theta bins, where the bin coordinate is linear in the angle.
NEBULA_HD float chord_phase_mean(const TableView& table, float tau_sct, float a0, float a1, int* clamps) {
  const float n = float(table.n_mu);
  // u = (1 - theta / pi) n - 1/2 (AngularBins::position), decreasing in a.
  const float u_lo = (0.5f - a1 * (1.0f / kPi)) * n - 0.5f, u_hi = (0.5f - a0 * (1.0f / kPi)) * n - 0.5f;
  return table.mean_over_angles(tau_sct, u_lo, u_hi, clamps);
}

// The distance from a star beyond which no chord of at most `chord` length
// spans kChordPhaseMinBins of n_mu angle bins: a chord at distance >= b from
// the star spans at most chord / b radians (d atan(s / b) / ds <= 1 / b), and
// the softened b of chord_irradiance is never below the geometric one. 1%
// above it for the rounding of the angles. 0 for n_mu = 0 (no such table).
inline float chord_phase_radius(float chord, int n_mu) {
  return 1.01f * chord * float(n_mu) / (kChordPhaseMinBins * kPi);
}

// How far from a star a ray counts as near (passes_near_a_star). The phase's
// radius grows with the longest chord a voxel can give the ray: a voxel of
// edge l cut along unit `dir` gives at most l / max_i |dir_i| (its slab
// across the dominant axis), the diagonal sqrt(3) l only along a diagonal,
// so a ray along an axis is near only within 1/sqrt(3) of the diagonal's
// radius. `fixed`: a radius that holds whatever the direction (the zonal
// field on the chords, raycast/march_scene.h).
struct NearStarRadius {
  float per_chord = 0.0f;  // chord_phase_radius per unit of chord length (0: no phase means)
  float voxel = 0.0f;      // the voxel's edge
  float fixed = 0.0f;
  // The phase's radius for the table's n_mu bins and voxels of edge l.
  static NearStarRadius phase(float l, int n_mu) { return {chord_phase_radius(1.0f, n_mu), l, 0.0f}; }
  // Along unit dir.
  NEBULA_HD float along(Vec3 dir) const {
    const float dominant = fmaxf(fabsf(dir.x), fmaxf(fabsf(dir.y), fabsf(dir.z)));
    const float phase = per_chord > 0.0f ? per_chord * voxel / dominant : 0.0f;
    return fmaxf(phase, fixed);
  }
};

// Whether a ray from `origin` along unit `dir` passes within `radius`
// (NearStarRadius::along) of one of the n stars (each with a .position), or
// within 4 of its pixel's widths there (the footprint): only such rays have
// chords whose angles chord_phase_mean averages or whose pixel's mean of 1/b
// needs its closed form (illumination/chord_irradiance.h), so the marchers
// march the others without them (their kernels keep their registers) and
// give the same image.
template <class Star>
NEBULA_HD bool passes_near_a_star(const Star* stars, int n, const NearStarRadius& radius,
                                  const RayFootprint& footprint, Vec3 origin, Vec3 dir) {
  const float r = radius.along(dir), r2 = r * r;
  for (int k = 0; k < n; ++k) {
    const Vec3 to_star = stars[k].position - origin;
    const float tc = dot(to_star, dir);
    // The line's distance, as chord_irradiance takes it (a star behind the
    // origin included); the chords' distance for the phase.
    const Vec3 off = to_star - tc * dir;
    const float w4 = 4.0f * footprint.width(tc);
    if (dot(off, off) < w4 * w4) return true;
    const Vec3 chords_off = tc > 0.0f ? off : to_star;
    if (dot(chords_off, chords_off) < r2) return true;
  }
  return false;
}

}  // namespace nebula
