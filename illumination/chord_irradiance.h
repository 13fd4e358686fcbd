#pragma once
// A star's irradiance over the chord a ray cuts through a cell (DESIGN.md
// section 3, "Ray marching"). The cell's light is E P(tau, theta) c / l with E
// proportional to 1 / r^2; near the star r changes by a large factor along
// one chord, and E at a single point of it (centre, midpoint) misses most of
// the light of a ray passing close to the star. So the marchers take the mean
// of 1 / r^2 over the chord, in closed form, and theta where the chord has
// received half of that light.
//
// A ray stands for its pixel: the pixels around a star hold the mean of the
// 1 / b profile of their rays' line integrals (b the ray's distance from the
// star), which diverges on the star's own line. Softening b^2 to b^2 + w^2 / (4
// pi), w the pixel's width at the star's distance, gives the exact mean over a
// round pixel of the same area centred on the star (0.55% above a square
// one's) and 1 / b far from it (docs/marcher.md).
#include "core/camera.h"
#include "core/hd.h"
#include "core/math.h"
#include "core/vec3.h"

namespace nebula {

struct ChordIrradiance {
  float inv_r2 = 0;  // mean of 1 / r^2 (softened) over the chord
  Vec3 point;        // where half of the chord's light has been received: theta is taken here
  // The angles atan((t - t_c) / b) at the chord's ends (a0 <= a1) where the
  // closed form below is taken (near the star), else both 0. The chord's light
  // is spread evenly over a in [a0, a1] (ds / (b^2 + s^2) = da / b), and the
  // scattering angle towards the eye is theta = pi/2 + a (ray_march.h,
  // chord_phase_mean).
  float a0 = 0, a1 = 0;
};

// The chord from origin + t0 dir to origin + t1 dir (unit dir) of a ray with
// this footprint, lit by a star at `star`.
NEBULA_HD ChordIrradiance chord_irradiance(Vec3 origin, Vec3 dir, float t0, float t1, Vec3 star,
                                           const RayFootprint& footprint) {
  ChordIrradiance out;
  const Vec3 to_star = star - origin;
  const float tc = dot(to_star, dir);  // the closest approach along the ray
  const Vec3 off = to_star - tc * dir;
  const float w = footprint.width(tc);
  // b^2 + w^2 / (4 pi), never 0 (a pixel has a width; a guard for a point camera).
  const float b2 = fmaxf(dot(off, off) + w * w * kInv4Pi, 1e-30f + 1e-12f * dot(to_star, to_star));
  const float chord = t1 - t0;
  const float mid = 0.5f * (t0 + t1) - tc;
  const float r2_mid = b2 + mid * mid;
  // Far from the star (half chord below 3% of r) the mean is 1 / r^2 at the
  // middle to within (chord / 2)^2 / r^2 < 0.1%: most cells take this branch and
  // skip the three transcendentals below.
  if (0.25f * chord * chord < 1e-3f * r2_mid) {
    out.inv_r2 = 1.0f / r2_mid;
    out.point = origin + (tc + mid) * dir;
    return out;
  }
  // Integral of ds / (b^2 + s^2) is atan(s / b) / b.
  const float b = sqrtf(b2);
  const float a0 = atanf((t0 - tc) / b), a1 = atanf((t1 - tc) / b);
  out.inv_r2 = (a1 - a0) / (b * chord);
  out.a0 = a0;
  out.a1 = a1;
  const float t = tc + b * tanf(0.5f * (a0 + a1));
  out.point = origin + fminf(fmaxf(t, t0), t1) * dir;
  return out;
}

// The same at one point (sampling marchers): 1 / r^2 there, r^2 softened by
// the footprint as above.
NEBULA_HD ChordIrradiance point_irradiance(Vec3 point, Vec3 star, float width) {
  const Vec3 d = point - star;
  return {1.0f / fmaxf(dot(d, d) + width * width * kInv4Pi, 1e-30f), point};
}

}  // namespace nebula
