#pragma once
// The ground truth (DESIGN.md section 3, "Ground truth"; docs/accuracy.md):
// an unbiased volumetric path tracer on exactly the scene the fast renderer
// sees. Written once for host and device; truth_renderer.cpp launches it with
// TBB, truth_renderer_cuda.cu with one CUDA thread per pixel.
//
// The medium is piecewise constant per voxel: in band b,
// sigma_ext = tau_v (A_b/A_V) / l, sigma_sct = a_b sigma_ext, HG(g_b) phase.
// Stars are isotropic point sources of band power Phi_b; emission j (the
// radiance a ray gains crossing one voxel edge) is an isotropic emission
// coefficient j / l per unit length. Each band is traced on its own paths.
//
// Estimators, all unbiased (no step size, no clamping of contributions):
// * free flights: delta tracking against the majorant grid (majorant_grid.h),
//   null collisions where the block's bound exceeds the voxel's sigma_ext;
// * at a real collision the path's weight is multiplied by the albedo (no
//   absorption sampling), next-event estimation to every star with residual
//   ratio tracking for the transmittance (control = the block's minimum,
//   tentative points at the block's max - min: a uniform block is crossed
//   exactly, with no tentative point at all), then an HG direction;
// * emission: at every path vertex (the camera included) the exact integral
//   of T(t) j/l along the whole ray to the grid's edge, voxel by voxel (the
//   medium is piecewise constant, so this is a closed form); the scattered
//   part of the radiance is what the collisions estimate. With a = 0 the
//   image is therefore exact and noise-free;
// * Russian roulette from the `roulette_start`-th collision on: survive with
//   probability min(1, weight), the survivor's weight divided by it.
// Two guards, both measure-zero in practice and counted where they act: a
// path is capped after kTruthMaxOrders collisions (counted), and a star
// closer than 1e-12 voxel edges to a collision sends nothing (keeps floats
// finite; the ball has probability ~1e-36).
#include <cstdint>

#include "core/bands.h"
#include "core/camera.h"
#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "core/math.h"
#include "core/philox.h"
#include "core/vec3.h"
#include "montecarlo/grid_transport.h"
#include "montecarlo/henyey_greenstein.h"

namespace nebula {

constexpr int kTruthMaxOrders = 100000;
constexpr uint32_t kPurposeTruth = 0x5054u;  // "PT"

struct TruthStarView {
  Vec3 position;
  float power[kMaxBands];  // band power, L_sun
  // Where the star appears in the image, in pixels from the top-left corner
  // (core/camera.h project_point); in_image false where it appears nowhere.
  float image_x = 0, image_y = 0;
  bool in_image = false;
};

// Everything a path needs, by value (pointers to host or device memory).
struct PathScene {
  DensityView density;
  MajorantView majorant;
  int n_bands = 0;
  float extinction_ratio[kMaxBands];  // A_b / A_V
  float albedo[kMaxBands];
  float g[kMaxBands];
  const float* emission[kMaxBands];   // j per voxel and band, or null
  const TruthStarView* stars = nullptr;
  int n_stars = 0;
  uint64_t seed = 1;
  int max_orders = 0;      // 0: unlimited (the truth); k > 0: orders 1..k only (tests, studies)
  int roulette_start = 3;  // collisions before Russian roulette plays
  bool exact_transmittance = false;  // NEE: exact DDA sum over voxels instead of ratio tracking
  bool equiangular = false;  // NEE also from equiangular samples towards each star, MIS with the collisions
  // Pixel-area sampling: sample k lies in stratum k mod side^2 of a side x
  // side grid over the pixel, at a uniform point in it (1: the pixel's centre).
  int pixel_side = 1;
  // A stratum that holds a star's image, or lies within one stratum of it,
  // draws its points with density proportional to 1 / (distance from the
  // image's nearest point of the stratum) (sample_stratum below);
  // false: uniformly, as every other stratum (tests compare the two).
  bool star_strata = true;
};

struct PathCounters {
  uint64_t vertices = 0;   // real collisions (path vertices with next-event estimation)
  uint64_t tentative = 0;  // tentative collisions of delta and ratio tracking
  uint64_t capped = 0;     // paths ended at kTruthMaxOrders
};

// Uniforms of one path: the stream (pixel, sample, purpose|band) under the
// scene's seed.
struct PathRng : UniformStream {
  NEBULA_HD PathRng(uint64_t seed_, uint32_t pixel, uint32_t sample, uint32_t band)
      : UniformStream(seed_, pixel, sample, (kPurposeTruth << 8) | band) {}
};

// The scene's dust as the shared transport code reads it.
NEBULA_HD GridMedium medium_of(const PathScene& s) { return GridMedium{s.density, s.majorant}; }

// Exact emission radiance along the ray from `origin` in band b to the grid's
// edge: sum over voxels of T_in (j / l) (1 - exp(-sigma c)) / sigma.
NEBULA_HD float emission_along(const PathScene& s, int b, float scale, Vec3 origin, Vec3 dir) {
  const float* j = s.emission[b];
  if (!j) return 0.0f;
  const GridShape& g = s.density.shape;
  const float inv_voxel = 1.0f / g.voxel;
  float radiance = 0.0f, depth = 0.0f;
  traverse_segment_cells(g, origin, origin + beyond_grid(g, origin) * dir,
                         [&](int, int, int, size_t cell, float chord) {
                           const float sigma = s.density.tau_v[cell] * scale;
                           const float od = sigma * chord;
                           // (1 - e^-od) / sigma, with its series where od is small.
                           const float path = od > 1e-3f ? -expm1f(-od) / sigma : chord * (1.0f - 0.5f * od);
                           radiance += expf(-depth) * j[cell] * inv_voxel * path;
                           depth += od;
                         });
  return radiance;
}

// Light from `star` scattered at x towards -dir per unit sigma_sct:
// Phi / (4 pi r^2) T(star -> x) p_HG(mu); 0 within 1e-12 voxel of the star.
template <class Rng>
NEBULA_HD float star_light(const PathScene& s, int b, float scale, Vec3 x, Vec3 dir, const TruthStarView& star,
                           Rng& rng, PathCounters& c) {
  const Vec3 d = x - star.position;  // the light's direction before scattering
  const float r2 = dot(d, d);
  const float near2 = 1e-24f * s.density.shape.voxel * s.density.shape.voxel;
  if (!(r2 > near2) || !(star.power[b] > 0.0f)) return 0.0f;
  const float mu = dot(d, -dir) / sqrtf(r2);  // after scattering it goes back along the path
  const float t = s.exact_transmittance
                      ? expf(-s.extinction_ratio[b] * segment_optical_depth(s.density, x, star.position))
                      : ratio_track(medium_of(s), scale, x, star.position, rng, c.tentative);
  return star.power[b] * kInv4Pi / r2 * t * hg_phase(s.g[b], mu);
}

// Equiangular sampling of a point on the ray o + t dir, t in [t0, t1], with
// density proportional to 1 / r^2 from a point c (Kulla & Fajardo 2012):
// its pdf cancels the star's 1/r^2, so the weights stay bounded near a star.
struct Equiangular {
  float delta = 0, dist = 0, theta0 = 0, theta1 = 0, t0 = 0, t1 = 0;
  bool ok = false;
  NEBULA_HD Equiangular(Vec3 o, Vec3 dir, Vec3 c, float t0_, float t1_, float min_dist) : t0(t0_), t1(t1_) {
    delta = dot(c - o, dir);
    dist = length(c - (o + delta * dir));
    if (!(dist > min_dist)) return;
    theta0 = atan2f(t0 - delta, dist);
    theta1 = atan2f(t1 - delta, dist);
    ok = theta1 > theta0;
  }
  NEBULA_HD float sample(float u) const { return delta + dist * tanf(theta0 + u * (theta1 - theta0)); }
  NEBULA_HD float pdf(float t) const {
    if (!ok || t < t0 || t > t1) return 0.0f;
    const float x = t - delta;
    return dist / ((theta1 - theta0) * (dist * dist + x * x));
  }
};

// One path of band b from `origin` along unit `dir`: its radiance estimate.
template <class Rng>
NEBULA_HD float trace_path(const PathScene& s, int b, Vec3 origin, Vec3 dir, Rng& rng, PathCounters& c) {
  const float a = s.albedo[b], g = s.g[b];
  const float scale = s.extinction_ratio[b] / s.density.shape.voxel;
  const bool emits = s.emission[b] != nullptr;
  const GridShape& grid = s.density.shape;
  const float min_dist = 1e-6f * grid.voxel;
  if (!emits && (s.n_stars == 0 || !(a > 0.0f))) return 0.0f;
  float weight = 1.0f, radiance = 0.0f;
  Vec3 pos = origin;
  for (int order = 0;;) {
    if (emits) radiance += weight * emission_along(s, b, scale, pos, dir);
    if (!(a > 0.0f)) break;
    // With equiangular sampling, next-event estimation on this segment has two
    // techniques per star, combined by the balance heuristic: a point drawn
    // towards the star (pdf p_e) and the delta-tracking collision (pdf
    // p_d(t) = sigma_ext(t) T(0, t)). Each contributes f / (p_e + p_d), with
    // f = T(0, t) sigma_sct(t) star_light(t); T(0, t) by the exact voxel sum.
    float seg0 = 0.0f, seg1 = 0.0f;
    const bool mis = s.equiangular && clip_to_grid(grid, pos, dir, beyond_grid(grid, pos), seg0, seg1);
    if (mis) {
      for (int k = 0; k < s.n_stars; ++k) {
        const Equiangular e(pos, dir, s.stars[k].position, seg0, seg1, min_dist);
        if (!e.ok) continue;
        const float te = e.sample(rng.next());
        const float pe = e.pdf(te);
        if (!(pe > 0.0f)) continue;
        const Vec3 xe = pos + te * dir;
        const float sigma = tau_v_at(s.density, xe) * scale;
        if (!(sigma > 0.0f)) continue;
        const float tr = expf(-s.extinction_ratio[b] * segment_optical_depth(s.density, pos, xe));
        const float f = tr * a * sigma * star_light(s, b, scale, xe, dir, s.stars[k], rng, c);
        radiance += weight * f / (pe + sigma * tr);
      }
    }
    const Vec3 from = pos;
    Vec3 hit;
    if (!delta_track(medium_of(s), scale, pos, dir, rng, hit, c.tentative)) break;
    pos = hit;
    ++order;
    ++c.vertices;
    float tr_hit = 1.0f, sigma_hit = 0.0f, t_hit = 0.0f;
    if (mis) {
      t_hit = length(hit - from);
      tr_hit = expf(-s.extinction_ratio[b] * segment_optical_depth(s.density, from, hit));
      sigma_hit = tau_v_at(s.density, hit) * scale;
    }
    for (int k = 0; k < s.n_stars; ++k) {
      const float light = star_light(s, b, scale, pos, dir, s.stars[k], rng, c);
      if (!(light > 0.0f)) continue;
      float pe = 0.0f;
      if (mis) pe = Equiangular(from, dir, s.stars[k].position, seg0, seg1, min_dist).pdf(t_hit);
      // Without the other technique (pe = 0) this is weight x a x light: the
      // collision estimator, sigma_sct T / (sigma_ext T).
      radiance += pe > 0.0f ? weight * tr_hit * a * sigma_hit * light / (sigma_hit * tr_hit + pe) : weight * a * light;
    }
    if (s.max_orders > 0 && order >= s.max_orders) break;
    if (order >= kTruthMaxOrders) {
      ++c.capped;
      break;
    }
    weight *= a;
    if (order >= s.roulette_start) {
      const float q = fminf(1.0f, weight);
      if (rng.next() >= q) break;
      weight /= q;
    }
    const float u0 = rng.next(), u1 = rng.next();
    float sin_phi, cos_phi;
    sin_cos_2pi(u1, sin_phi, cos_phi);
    // HG is symmetric in its two directions: sampling about the path's
    // direction is sampling the light's deflection.
    dir = scatter_direction(dir, hg_sample(g, u0), sin_phi, cos_phi);
  }
  return radiance;
}

// A point of the square stratum [x0, x0 + h] x [y0, y0 + h] (image pixels) and
// its weight, the uniform density over the square divided by the density drawn
// with: E[weight f(point)] is the square's mean of f.
struct StratumPoint {
  float x, y, weight;
};

// A point drawn with density 1 / (Z rho) about (px, py), which lies in the
// square (closed), rho the distance from it: the rays through a stratum that
// holds a star's image pass at impact parameters b ~ rho, and their light
// grows as 1/b (the equiangular estimate of a ray through dust at the star),
// whose square has a logarithmically divergent mean over the square; with
// this density each sample's weight Z rho / h^2 cancels it. The square is cut
// into four triangles with apex (px, py), one per edge at height H from it;
// a triangle's share of Z is the integral over its angles of the distance to
// its edge, H (asinh(bB / H) - asinh(bA / H)), bA < bB the edge's ends'
// offsets along it from the foot of the height. Within a triangle the angle
// is drawn uniform in s = asinh(b / H) (density proportional to the distance
// to the edge) and the point uniform along the line from the apex to the edge.
NEBULA_HD StratumPoint sample_stratum_about(float x0, float y0, float h, float px, float py, float u0, float u1,
                                            float u2) {
  // Edges right, top, left, bottom: outward normal n, height H from the apex,
  // direction t along the edge, its two corners' offsets along t from the foot.
  const float nx[4] = {1, 0, -1, 0}, ny[4] = {0, -1, 0, 1};
  const float H[4] = {x0 + h - px, py - y0, px - x0, y0 + h - py};
  const float cx[4][2] = {{x0 + h, x0 + h}, {x0, x0 + h}, {x0, x0}, {x0, x0 + h}};
  const float cy[4][2] = {{y0, y0 + h}, {y0, y0}, {y0, y0 + h}, {y0 + h, y0 + h}};
  float lo[4], hi[4], W[4], Z = 0.0f;
  for (int e = 0; e < 4; ++e) {
    const float tx = -ny[e], ty = nx[e];
    const float pa = (cx[e][0] - px) * tx + (cy[e][0] - py) * ty, pb = (cx[e][1] - px) * tx + (cy[e][1] - py) * ty;
    lo[e] = fminf(pa, pb);
    hi[e] = fmaxf(pa, pb);
    W[e] = H[e] > 1e-7f * h ? H[e] * (asinhf(hi[e] / H[e]) - asinhf(lo[e] / H[e])) : 0.0f;
    Z += W[e];
  }
  // The triangle: u0 through the cumulative shares (none of zero share).
  float target = u0 * Z;
  int e = 0;
  while (e < 3 && (target >= W[e] || W[e] == 0.0f)) {
    target -= W[e];
    ++e;
  }
  while (W[e] == 0.0f) e = (e + 3) % 4;  // u0 rounded past the last share
  const float tx = -ny[e], ty = nx[e];
  const float s0 = asinhf(lo[e] / H[e]), s1 = asinhf(hi[e] / H[e]);
  const float b = H[e] * sinhf(s0 + u1 * (s1 - s0));
  // The point on the edge (the foot of the height plus b along it), then
  // uniform along the way from the apex to it.
  const float qx = H[e] * nx[e] + b * tx, qy = H[e] * ny[e] + b * ty;
  const float rho = u2 * sqrtf(qx * qx + qy * qy);
  StratumPoint out;
  out.x = fminf(fmaxf(px + u2 * qx, x0), x0 + h);
  out.y = fminf(fmaxf(py + u2 * qy, y0), y0 + h);
  out.weight = Z * rho / (h * h);
  return out;
}

// Sample point of stratum [x0, x0 + h]^2: about the first star whose image
// lies in it or within one side h of it (star_strata), else uniform (weight
// 1). An image outside the square is drawn about its nearest point of the
// square, P': every point X of the (convex) square has |X - P| >= |X - P'|,
// so the weight still bounds the 1/b of the rays there. A star on four
// pixels' common corner lies, after rounding, a hair outside three of the four
// strata that touch it; drawn uniformly, those gave the rare huge samples.
NEBULA_HD StratumPoint sample_stratum(const PathScene& s, float x0, float y0, float h, float u0, float u1,
                                      float u2) {
  if (s.star_strata)
    for (int k = 0; k < s.n_stars; ++k) {
      const TruthStarView& star = s.stars[k];
      if (!star.in_image) continue;
      const float px = fminf(fmaxf(star.image_x, x0), x0 + h), py = fminf(fmaxf(star.image_y, y0), y0 + h);
      if (fabsf(star.image_x - px) <= h && fabsf(star.image_y - py) <= h)
        return sample_stratum_about(x0, y0, h, px, py, u0, u1, u2);
    }
  return StratumPoint{x0 + u0 * h, y0 + u1 * h, 1.0f};
}

// Samples [k0, k1) of pixel (x, y): per band the sum of the samples and of
// their squares, in double. The samples depend only on (pixel, sample,
// band), never on how a launch splits the range (the GPU gives a small
// image's pixels to several threads each: truth_renderer_cuda.cu).
struct PixelSums {
  double sum[kMaxBands];
  double sum2[kMaxBands];
};

NEBULA_HD void trace_pixel_samples(const PathScene& s, const Camera& camera, int x, int y, int k0, int k1,
                                   PixelSums& out, PathCounters& c) {
  for (int b = 0; b < kMaxBands; ++b) out.sum[b] = out.sum2[b] = 0.0;
  Vec3 origin, dir;
  const bool centre = camera.ray(x, y, origin, dir);
  if (!centre && s.pixel_side == 1) return;
  const uint32_t pixel = static_cast<uint32_t>(y) * static_cast<uint32_t>(camera.width) + static_cast<uint32_t>(x);
  const int strata = s.pixel_side * s.pixel_side;
  const float h = 1.0f / float(s.pixel_side);
  for (int b = 0; b < s.n_bands; ++b) {
    double sum = 0.0, sum2 = 0.0;
    for (int k = k0; k < k1; ++k) {
      double weight = 1.0;
      if (strata > 1) {
        // The same sub-pixel point in every band (its own stream, band 0xFF).
        PathRng jitter(s.seed, pixel, static_cast<uint32_t>(k), 0xFFu);
        const int stratum = k % strata;
        const float u0 = jitter.next(), u1 = jitter.next(), u2 = jitter.next();
        const StratumPoint p =
            sample_stratum(s, x + (stratum % s.pixel_side) * h, y + (stratum / s.pixel_side) * h, h, u0, u1, u2);
        weight = p.weight;
        if (!camera.ray_through(p.x, p.y, origin, dir)) continue;  // outside the dome: no light (a zero sample)
      }
      PathRng rng(s.seed, pixel, static_cast<uint32_t>(k), static_cast<uint32_t>(b));
      const double v = weight * trace_path(s, b, origin, dir, rng, c);
      sum += v;
      sum2 += v * v;
    }
    out.sum[b] = sum;
    out.sum2[b] = sum2;
  }
}

// A pixel's mean and the variance of that mean per band (exposure applied)
// from the sums of all its spp >= 2 samples.
NEBULA_HD void pixel_moments(const PixelSums& p, int n_bands, int spp, float exposure, float* mean, float* variance) {
  for (int b = 0; b < kMaxBands; ++b) mean[b] = variance[b] = 0.0f;
  const double n = spp;
  for (int b = 0; b < n_bands; ++b) {
    const double m = p.sum[b] / n;
    const double var = (p.sum2[b] - p.sum[b] * m) / (n * (n - 1.0));
    mean[b] = static_cast<float>(exposure * m);
    variance[b] = static_cast<float>(double(exposure) * exposure * (var > 0.0 ? var : 0.0));
  }
}

// All samples of pixel (x, y): mean and variance of the mean per band
// (exposure applied), from double sums. spp >= 2, a multiple of the strata
// (pixel_side^2): stratified samples make this variance an upper bound.
NEBULA_HD void trace_pixel(const PathScene& s, const Camera& camera, float exposure, int x, int y, int spp,
                           float* mean, float* variance, PathCounters& c) {
  PixelSums p;
  trace_pixel_samples(s, camera, x, y, 0, spp, p, c);
  pixel_moments(p, s.n_bands, spp, exposure, mean, variance);
}

}  // namespace nebula
