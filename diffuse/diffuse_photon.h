#pragma once
// One photon of the diffuse bake (docs/diffuse.md), written once for host and
// device: emitted by a star, its first collision forced, then traced by delta
// tracking (montecarlo/grid_transport.h) with Henyey-Greenstein scattering,
// weight x albedo at each collision and Russian roulette. Every flight after a
// collision deposits, into the field's cells it crosses, its weight x chord x
// Y_k(direction): the track-length estimator of the harmonics of the radiance
// entering each voxel. What a flight deposits:
//   * nothing of the first flight (from the star): direct light, which the
//     marcher takes from the per-star bake;
//   * nothing inside the voxel where the flight starts: light scattered in a
//     voxel and still inside it is that voxel's own multiple scattering,
//     which its table holds;
//   * the whole chord of the voxel where the flight ends in a collision, as
//     of every voxel it crosses before: the radiance *entering* a voxel is
//     wanted, before its own dust (which the table also holds) acts on it.
// Deposits are 36.28 fixed-point integers, so sums do not depend on the order
// of the additions: the same field for any thread count or launch shape.
// Several albedos can share one pass (a sweep over the albedo): the photons
// are traced at the largest, and a_k's field is the sum over n of
// (a_k / a_max)^n x the deposits of flights after collision n, an unbiased
// estimate for each a_k. Flights after the first few collisions deposit into
// one accumulator per order (the albedos' weights applied afterwards: the
// cost of one albedo), later ones into one per albedo with the weight
// applied (DiffuseSlots); the albedo that is the traced one gets the plain
// pass's sums bit for bit.
#include <cstdint>

#include "core/dda.h"
#include "core/grid.h"
#include "core/hd.h"
#include "core/math.h"
#include "core/philox.h"
#include "diffuse/spherical_harmonics.h"
#include "montecarlo/grid_transport.h"
#include "montecarlo/henyey_greenstein.h"

namespace nebula {

constexpr uint32_t kPurposeDiffuse = 0x4446u;  // "DF"
constexpr int kDiffuseMaxOrders = 10000;  // a photon is stopped (and counted) beyond this
constexpr float kDiffuseFixedScale = 268435456.0f;  // 2^28: one unit of weight x cell edge
constexpr int kMaxAlbedoSlots = 16;  // albedos one pass deposits for
constexpr int kMaxOrderBuckets = 32;  // orders a shared pass deposits once for every albedo (DiffuseSlots)

// One band's photon pass, by value (host or device pointers).
struct DiffusePhotonScene {
  GridMedium medium;
  float ratio = 1;       // A_b / A_V
  float albedo = 0, g = 0;
  GridShape cells;       // the field's cells
  int degree = 0;
  int n_coeffs = 1;      // per cell: the harmonics, then each zonal star's block
  int n_sh = 1;          // the harmonics' share, (degree + 1)^2
  // Zonal degrees degree + 1 .. zonal about the direction from star k < zonal_stars
  // to the cell's centre (0: none): block k at n_sh + k x (zonal - degree).
  int zonal = 0;
  int zonal_stars = 0;
  const Vec3* stars = nullptr;     // positions
  const float* star_cdf = nullptr; // cumulative band power fractions, last = 1
  int n_stars = 0;
  uint64_t seed = 1;
  uint32_t band = 0;  // the photons' random streams (DiffusePassInputs::stream)
  int roulette_start = 3;
  int max_orders = 0;   // 0: every order; k > 0: flights after collisions 1..k only (tests, studies)
  // Albedos deposited for (DiffuseSlots): slot k's scale a_k / albedo <= 1.
  int slots = 1;
  int order_buckets = 0;  // orders with an accumulator of their own (0 with one slot)
  float slot_scale[kMaxAlbedoSlots] = {1.0f};
};

// Where a shared pass's deposits go. Entry j of a cell (j < n_coeffs; the
// odd sums are the same layout with n_coeffs = 1):
//   flights after collision n <= buckets: [((n - 1) x cells + cell) x n_coeffs + j], unweighted;
//   later flights, weighted by scale_k^n:  [buckets x cells x n_coeffs + (cell x slots + k) x n_coeffs + j].
// One slot and no buckets: [cell x n_coeffs + j], the plain pass.
struct DiffuseSlots {
  size_t cells = 0;
  int n_coeffs = 1, buckets = 0, slots = 1;
  double scale[kMaxAlbedoSlots] = {1.0};
  NEBULA_HD size_t entries() const { return (size_t(buckets) + size_t(slots)) * cells * size_t(n_coeffs); }
  NEBULA_HD size_t bucket_index(int order, size_t cell, int j) const {
    return (size_t(order - 1) * cells + cell) * size_t(n_coeffs) + size_t(j);
  }
  NEBULA_HD size_t slot_index(int k, size_t cell, int j) const {
    return size_t(buckets) * cells * size_t(n_coeffs) + (cell * size_t(slots) + size_t(k)) * size_t(n_coeffs) + size_t(j);
  }
  // Slot k's sum of entry j in fixed-point units: the tail plus scale^n x
  // each bucket; an exact integer sum where the scale is 1.
  NEBULA_HD double sum(const unsigned long long* sums, int k, size_t cell, int j) const {
    if (scale[k] == 1.0) {
      unsigned long long total = sums[slot_index(k, cell, j)];
      for (int n = 1; n <= buckets; ++n) total += sums[bucket_index(n, cell, j)];
      return double(static_cast<long long>(total));
    }
    double total = double(static_cast<long long>(sums[slot_index(k, cell, j)])), power = 1.0;
    for (int n = 1; n <= buckets; ++n) {
      power *= scale[k];
      total += power * double(static_cast<long long>(sums[bucket_index(n, cell, j)]));
    }
    return total;
  }
};

struct PhotonCounters {
  uint64_t collisions = 0;  // real collisions after the first
  uint64_t tentative = 0;   // tentative collisions of delta tracking
  uint64_t crossings = 0;   // field cells a deposit crossed
  uint64_t capped = 0;      // photons stopped at kDiffuseMaxOrders
};

// Distance along unit `dir` from p to where it leaves the voxel holding p.
NEBULA_HD float voxel_exit(const GridShape& g, Vec3 p, Vec3 dir) {
  const int n[3] = {g.nx, g.ny, g.nz};
  float t = 3.0e38f;
  for (int k = 0; k < 3; ++k) {
    const float o = detail::axis(g.origin, k), pk = detail::axis(p, k), dk = detail::axis(dir, k);
    int i = static_cast<int>(floorf((pk - o) / g.voxel));
    i = i < 0 ? 0 : (i >= n[k] ? n[k] - 1 : i);
    const float lo = o + g.voxel * float(i), hi = lo + g.voxel;
    if (dk > 0.0f) t = fminf(t, (hi - pk) / dk);
    if (dk < 0.0f) t = fminf(t, (lo - pk) / dk);
  }
  return fmaxf(t, 0.0f);
}

// The point where the ray from `origin` along `dir` has crossed V-band depth
// `target` x (A_V/A_b) (band depth `target`), walking the voxels exactly.
NEBULA_HD Vec3 point_at_depth(const DensityView& d, float ratio, Vec3 origin, Vec3 dir, float far, float target) {
  const float inv_l = ratio / d.shape.voxel;
  float t0, t1;
  clip_to_grid(d.shape, origin, dir, far, t0, t1);
  float t = t0, depth = 0.0f, hit = t1;
  traverse_segment_cells(d.shape, origin + t0 * dir, origin + t1 * dir,
                         [&](int, int, int, size_t cell, float chord) -> bool {
                           const float sigma = d.tau_v[cell] * inv_l;
                           const float step = sigma * chord;
                           if (depth + step >= target && sigma > 0.0f) {
                             hit = t + (target - depth) / sigma;
                             return false;
                           }
                           depth += step;
                           t += chord;
                           return true;
                         });
  return origin + fminf(hit, t1) * dir;
}

// Traces photon `photon` of the band; deposit(index, fixed_value) adds to
// accumulator `index` = cell * n_coeffs + k. `odd` receives the l = 0 deposits
// of odd photons again (the field's noise from its two halves).
// kShared: the scene has several slots (DiffuseSlots); false compiles the
// plain pass, with nothing of the slots in it. kZonal: the scene has zonal
// degrees (their deposits are a separate instantiation too: a local array
// of them per crossing tripled the plain pass's time on the GPU).
template <bool kShared = false, bool kZonal = false, class Deposit, class DepositOdd>
NEBULA_HD void trace_diffuse_photon(const DiffusePhotonScene& s, uint32_t photon, Deposit&& deposit,
                                    DepositOdd&& deposit_odd, PhotonCounters& c) {
  if (s.n_stars == 0 || !(s.albedo > 0.0f)) return;
  UniformStream rng(s.seed, photon, s.band, kPurposeDiffuse);
  const DensityView& dens = s.medium.density;
  const GridShape& g = dens.shape;
  // The star, by band power.
  const float u_star = rng.next();
  int k = 0;
  while (k < s.n_stars - 1 && u_star > s.star_cdf[k]) ++k;
  const Vec3 origin = s.stars[k];
  // Emission: isotropic, or into the cone of the grid's bounding sphere when
  // the star is outside it (weight: the cone's share of all directions).
  const Vec3 centre = g.origin + 0.5f * (g.upper() - g.origin);
  const float radius = 0.5f * length(g.upper() - g.origin);
  const Vec3 to_centre = centre - origin;
  const float distance = length(to_centre);
  float weight = 1.0f;
  float cos_theta, sin_phi, cos_phi;
  Vec3 axis{0.0f, 0.0f, 1.0f};
  const float u0 = rng.next(), u1 = rng.next();
  sin_cos_2pi(u1, sin_phi, cos_phi);
  if (distance > radius * 1.0001f) {
    const float cos_max = sqrtf(fmaxf(0.0f, 1.0f - (radius / distance) * (radius / distance)));
    cos_theta = 1.0f - u0 * (1.0f - cos_max);
    weight = 0.5f * (1.0f - cos_max);
    axis = (1.0f / distance) * to_centre;
  } else {
    cos_theta = 1.0f - 2.0f * u0;
  }
  Vec3 dir = scatter_direction(axis, HgSample{cos_theta, sqrtf(fmaxf(0.0f, 1.0f - cos_theta * cos_theta))}, sin_phi,
                               cos_phi);
  // The first collision, forced: weight x (1 - exp(-tau)) along the whole ray.
  const float far = beyond_grid(g, origin);
  const float tau = s.ratio * segment_optical_depth(dens, origin, origin + far * dir);
  if (!(tau > 0.0f)) return;
  const float interacts = -expm1f(-tau);
  weight *= interacts;
  const float target = -log1pf(-rng.next() * interacts);
  Vec3 pos = point_at_depth(dens, s.ratio, origin, dir, far, target);
  const float scale = s.ratio / g.voxel;
  const bool odd = (photon & 1u) != 0u;
  float y[kMaxShCoeffs];
  float slot_factor[kMaxAlbedoSlots];  // slot_scale^order
  if constexpr (kShared)
    for (int k = 0; k < s.slots; ++k) slot_factor[k] = 1.0f;
  const size_t n_cells = s.cells.count();
  const size_t tail = size_t(s.order_buckets) * n_cells;  // the slots' entries follow the buckets'

  for (int order = 1;; ++order) {
    weight *= s.albedo;
    if constexpr (kShared)
      for (int k = 0; k < s.slots; ++k) slot_factor[k] *= s.slot_scale[k];
    if (!(weight > 0.0f)) break;
    if (order >= s.roulette_start) {
      const float q = fminf(1.0f, weight);
      if (rng.next() >= q) break;
      weight /= q;
    }
    if (order > kDiffuseMaxOrders) {
      ++c.capped;
      break;
    }
    const float ua = rng.next(), ub = rng.next();
    float sp, cp;
    sin_cos_2pi(ub, sp, cp);
    dir = scatter_direction(dir, hg_sample(s.g, ua), sp, cp);
    Vec3 hit;
    const bool collided = delta_track(s.medium, scale, pos, dir, rng, hit, c.tentative);
    // Deposit from where the flight leaves its first voxel to where it leaves
    // the voxel of its collision (or the grid).
    float t_end;
    if (collided) {
      t_end = length(hit - pos) + voxel_exit(g, hit, dir);
    } else {
      float t0, t1;
      t_end = clip_to_grid(g, pos, dir, beyond_grid(g, pos), t0, t1) ? t1 : 0.0f;
    }
    const float t_start = voxel_exit(g, pos, dir);
    if (t_end > t_start) {
      sh_basis(s.degree, dir, y);
      const float inv_edge = 1.0f / s.cells.voxel;
      [[maybe_unused]] const int n_zonal = kZonal && s.zonal > s.degree && k < s.zonal_stars ? s.zonal - s.degree : 0;
      [[maybe_unused]] const int zonal_at = s.n_sh + k * (s.zonal - s.degree);
      const Vec3 seg_start = pos + t_start * dir;
      [[maybe_unused]] float along = 0.0f;  // the chord's start, from seg_start (zonal degrees)
      traverse_segment_cells(s.cells, seg_start, pos + t_end * dir,
                             [&](int, int, int, size_t cell, float chord) {
                               ++c.crossings;
                               const float w_all = weight * chord * inv_edge * kDiffuseFixedScale;
                               [[maybe_unused]] float z[kZonal ? kMaxZonalDegree : 1];
                               if constexpr (kZonal) {
                                 const float mid = along + 0.5f * chord;
                                 along += chord;
                                 if (n_zonal > 0) {
                                   // About the direction from the star to the chord's middle.
                                   const Vec3 r = seg_start + mid * dir - origin;
                                   const float len = length(r);
                                   zonal_basis(s.degree + 1, s.zonal, len > 0.0f ? dot(dir, r) / len : dir.z, z);
                                 }
                               }
                               // Entry 0 of the cell's block at `base`, weight w.
                               auto put = [&](size_t base, float w) {
                                 for (int j = 0; j < s.n_sh; ++j)
                                   deposit(base + size_t(j), static_cast<unsigned long long>(llrintf(w * y[j])));
                                 if constexpr (kZonal)
                                   for (int j = 0; j < n_zonal; ++j)
                                     deposit(base + size_t(zonal_at + j),
                                             static_cast<unsigned long long>(llrintf(w * z[j])));
                               };
                               if constexpr (!kShared) {
                                 put(cell * size_t(s.n_coeffs), w_all);
                                 if (odd) deposit_odd(cell, static_cast<unsigned long long>(llrintf(w_all * y[0])));
                                 return;
                               }
                               if (order <= s.order_buckets) {  // one accumulator for every albedo
                                 const size_t at = size_t(order - 1) * n_cells + cell;
                                 put(at * size_t(s.n_coeffs), w_all);
                                 if (odd) deposit_odd(at, static_cast<unsigned long long>(llrintf(w_all * y[0])));
                                 return;
                               }
                               for (int k = 0; k < s.slots; ++k) {
                                 const float w = w_all * slot_factor[k];
                                 const size_t slot = cell * size_t(s.slots) + size_t(k);
                                 put((tail + slot) * size_t(s.n_coeffs), w);
                                 if (odd) deposit_odd(tail + slot, static_cast<unsigned long long>(llrintf(w * y[0])));
                               }
                             });
    }
    if (!collided || (s.max_orders > 0 && order >= s.max_orders)) break;
    pos = hit;
    ++c.collisions;
  }
}

}  // namespace nebula
