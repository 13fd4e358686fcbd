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
// star), which diverges on the star's own line. The marchers replace b by
// 1 / (the mean of 1 / b over the square pixel around the ray, at the star's
// distance), in closed form (pixel_mean_b2); a fisheye's pixels, with no fixed
// sides, soften b^2 to b^2 + w^2 / (4 pi), the mean over a round pixel centred on
// the star (docs/marcher.md).
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

// The integral of 1 / sqrt(x^2 + y^2) over [0, x] x [0, y], odd in x and in y
// (so that a rectangle's integral is the difference of its corners'):
// x asinh(y / x) + y asinh(x / y).
NEBULA_HD float inverse_distance_corner(float x, float y) {
  const float ax = fabsf(x), ay = fabsf(y);
  float v = 0.0f;
  if (ax > 0.0f) v += ax * asinhf(ay / ax);
  if (ay > 0.0f) v += ay * asinhf(ax / ay);
  return (x < 0.0f) != (y < 0.0f) ? -v : v;
}

// The mean of 1 / |(x, y) + (u, v)| over a unit square pixel, (u, v) in
// [-1/2, 1/2]^2: 2 asinh(1) / (1/2) = 3.5255 at its centre, 1.7627 at its
// corner, 1 / sqrt(x^2 + y^2 - 1/12) within 0.01% beyond 3 widths.
NEBULA_HD float square_pixel_mean_inverse_distance(float x, float y) {
  return inverse_distance_corner(x + 0.5f, y + 0.5f) - inverse_distance_corner(x - 0.5f, y + 0.5f) -
         inverse_distance_corner(x + 0.5f, y - 0.5f) + inverse_distance_corner(x - 0.5f, y - 0.5f);
}

// b^2 for a ray whose pixel is w wide at the star, `off` the star's offset from
// the ray (perpendicular to it): 1 / (the pixel's mean of 1 / b)^2. Beyond 4
// widths b^2 - w^2 / 12 (within 0.003%), without the transcendentals.
// kNearStar false: for a ray that passes no star within 4 widths
// (passes_near_a_star, tables/chord_phase.h), whose kernel then carries none of
// the closed form (given a star within them, it softens as a round pixel).
template <bool kNearStar = true>
NEBULA_HD float pixel_mean_b2(Vec3 off, float w, const RayFootprint& footprint) {
  const float b2 = dot(off, off), w2 = w * w;
  if (b2 >= 16.0f * w2) return b2 - w2 * (1.0f / 12.0f);
  const bool sides = dot(footprint.side_x, footprint.side_x) > 0.0f;
  if (!kNearStar || !sides) return b2 + w2 * kInv4Pi;
  const float inv_w = 1.0f / w;
  const float mean = square_pixel_mean_inverse_distance(dot(off, footprint.side_x) * inv_w,
                                                        dot(off, footprint.side_y) * inv_w);
  return w2 / (mean * mean);
}

// What chord_irradiance needs of a star that does not change along a ray: the
// closest approach tc and the pixel's b^2 there; closed_form: b^2 took
// pixel_mean_b2's closed form (eight asinh), which a march near a star's image
// takes once per ray (NearStar below) rather than at every cell of the ray.
struct StarOnRay {
  float tc = 0, b2 = 0;
  bool closed_form = false;
};
template <bool kNearStar = true>
NEBULA_HD StarOnRay star_on_ray(Vec3 origin, Vec3 dir, Vec3 star, const RayFootprint& footprint) {
  const Vec3 to_star = star - origin;
  const float tc = dot(to_star, dir);  // the closest approach along the ray
  const Vec3 off = to_star - tc * dir;
  const float w = footprint.width(tc);
  // The pixel's b^2, never 0 (a pixel has a width; a guard for a point camera).
  return {tc, fmaxf(pixel_mean_b2<kNearStar>(off, w, footprint), 1e-30f + 1e-12f * dot(to_star, to_star)),
          kNearStar && dot(off, off) < 16.0f * w * w};
}

// The chord from origin + t0 dir to origin + t1 dir (unit dir) of a ray, lit
// by a star at `star` (star_on_ray of the same ray).
NEBULA_HD ChordIrradiance chord_irradiance(const StarOnRay& star, Vec3 origin, Vec3 dir, float t0, float t1) {
  ChordIrradiance out;
  const float tc = star.tc, b2 = star.b2;
  const float chord = t1 - t0;
  const float mid = 0.5f * (t0 + t1) - tc;
  const float r2_mid = b2 + mid * mid;
  // Far from the star (half chord below 3% of r) the mean is 1 / r^2 at the
  // middle to within (chord / 2)^2 / r^2 < 0.1%: most cells take this branch and
  // skip the three transcendentals below.
  if (0.25f * chord * chord < 1e-3f * r2_mid) {
    out.inv_r2 = reciprocal(r2_mid);
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

// The same for a ray with this footprint and a star at `star`. kNearStar as
// pixel_mean_b2's.
template <bool kNearStar = true>
NEBULA_HD ChordIrradiance chord_irradiance(Vec3 origin, Vec3 dir, float t0, float t1, Vec3 star,
                                           const RayFootprint& footprint) {
  return chord_irradiance(star_on_ray<kNearStar>(origin, dir, star, footprint), origin, dir, t0, t1);
}

// The first of a ray's stars (each with a .position) whose b^2 takes the closed
// form, with its StarOnRay, taken once when the ray starts (k = -1: none, and
// always without kNearStar). Rays at a star's image would otherwise take the
// eight asinh at every cell: on an H200 they were the frame's longest rays.
struct NearStar {
  int k = -1;
  StarOnRay on_ray;
};
template <bool kNearStar, class Star>
NEBULA_HD NearStar near_star(const Star* stars, int n, Vec3 origin, Vec3 dir, const RayFootprint& footprint) {
  NearStar out;
  if constexpr (kNearStar)
    for (int k = 0; k < n; ++k) {
      const StarOnRay s = star_on_ray<true>(origin, dir, stars[k].position, footprint);
      if (s.closed_form) {
        out.k = k;
        out.on_ray = s;
        break;
      }
    }
  return out;
}
// chord_irradiance<kNearStar> for star k at `star`, from `near` where it is that star.
template <bool kNearStar>
NEBULA_HD ChordIrradiance chord_irradiance(const NearStar& near, int k, Vec3 star, Vec3 origin, Vec3 dir, float t0,
                                           float t1, const RayFootprint& footprint) {
  if (kNearStar && k == near.k) return chord_irradiance(near.on_ray, origin, dir, t0, t1);
  return chord_irradiance<kNearStar>(origin, dir, t0, t1, star, footprint);
}

// The same at one point (sampling marchers): 1 / r^2 there, r^2 softened by
// the footprint as above.
NEBULA_HD ChordIrradiance point_irradiance(Vec3 point, Vec3 star, float width) {
  const Vec3 d = point - star;
  return {1.0f / fmaxf(dot(d, d) + width * width * kInv4Pi, 1e-30f), point};
}

}  // namespace nebula
