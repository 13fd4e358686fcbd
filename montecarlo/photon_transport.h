#pragma once
// Photon transport with the Henyey-Greenstein phase function, written once
// for host and device (DESIGN.md section 3, "Table").
//
// Free paths are sampled with the extinction coefficient; at each scattering
// the weight is multiplied by the albedo, so absorption along every segment is
// exact in expectation. Unbiased Russian roulette ends low-weight photons, and
// a cap on scattering orders ends (and counts) the pathological rest. With
// forced first scattering the first free path is drawn from the exponential
// truncated to the chord, the weight carrying the interaction probability and
// the unscattered remainder going to its own tally: unbiased, and far less
// noisy for optically thin voxels where most analog photons never scatter.
#include <cmath>
#include <cstdint>

#include "core/hd.h"
#include "core/philox.h"
#include "core/vec3.h"
#include "montecarlo/henyey_greenstein.h"

namespace nebula {

struct Medium {
  float sigma_ext;  // extinction coefficient, per unit length
  float albedo;     // single-scattering albedo
  float g;          // HG asymmetry
};

struct Roulette {
  float threshold = 1e-3f;  // albedo weight below which roulette is played
  float survival = 0.1f;    // survival probability; survivors' weight / survival
  int max_orders = 10000;   // scattering orders after which a photon is capped
};

// Sphere of the given radius centred at the origin; the photon is inside.
struct SphereGeometry {
  float radius;
  NEBULA_HD float exit_distance(Vec3 p, Vec3 d) const {
    const float b = dot(p, d);
    const float c = dot(p, p) - radius * radius;  // <= 0 inside, up to rounding
    const float root = sqrtf(fmaxf(b * b - c, 0.0f));
    // Two algebraically equal roots; the one chosen never subtracts near-equal numbers.
    const float t = b > 0.0f ? -c / (b + root) : root - b;
    return fmaxf(t, 0.0f);
  }
};

// Plane-parallel slab 0 <= z <= thickness, infinite in x and y.
struct SlabGeometry {
  float thickness;
  NEBULA_HD float exit_distance(Vec3 p, Vec3 d) const {
    float t = 3.0e38f;  // parallel to the faces: never leaves
    if (d.z > 0.0f) t = (thickness - p.z) / d.z;
    if (d.z < 0.0f) t = -p.z / d.z;
    return fmaxf(t, 0.0f);
  }
};

struct PhotonState {
  Vec3 pos;
  Vec3 dir;
  float weight_forced = 1;  // probability of the forced first interaction (1 if analog)
  float weight_albedo = 1;  // product of albedos and roulette factors
  uint32_t draw = 1;        // next Philox block; block 0 belongs to the launch
  int orders = 0;           // scatterings so far
  NEBULA_HD float weight() const { return weight_forced * weight_albedo; }
};

enum class Fate : int { Flying = 0, Escaped, Absorbed, Capped };

// The first flight from the entry point. Returns the weight that leaves
// unscattered; `alive` tells whether a scattering follows at st.pos.
template <class Geometry>
NEBULA_HD float first_flight(const Geometry& geometry, const Medium& m, bool forced, float u_path,
                             PhotonState& st, bool& alive) {
  const float d = geometry.exit_distance(st.pos, st.dir);
  const float optical = m.sigma_ext * d;
  if (forced) {
    const float p_interact = -expm1f(-optical);
    if (!(p_interact > 0.0f)) {
      alive = false;
      return 1.0f;
    }
    const float s = -log1pf(-u_path * p_interact) / m.sigma_ext;
    st.pos = st.pos + fminf(s, d) * st.dir;
    st.weight_forced = p_interact;
    alive = true;
    return expf(-optical);
  }
  const float s = -logf(u_path) / m.sigma_ext;
  if (!(s < d)) {
    alive = false;
    return 1.0f;
  }
  st.pos = st.pos + s * st.dir;
  st.weight_forced = 1.0f;
  alive = true;
  return 0.0f;
}

// Scatters at st.pos, plays roulette, and flies to the next interaction or out.
// Uses one Philox block: u0 polar angle, u1 azimuth, u2 free path, u3 roulette.
template <class Geometry>
NEBULA_HD Fate scatter_and_fly(const Geometry& geometry, const Medium& m, const Roulette& rr,
                               const Uniform4& u, PhotonState& st) {
  st.weight_albedo *= m.albedo;
  st.dir = scatter_direction(st.dir, hg_sample(m.g, u.u0), u.u1);
  ++st.orders;
  if (st.weight_albedo < rr.threshold) {
    if (u.u3 >= rr.survival) return Fate::Absorbed;
    st.weight_albedo /= rr.survival;
  }
  const float d = geometry.exit_distance(st.pos, st.dir);
  const float s = -logf(u.u2) / m.sigma_ext;
  if (!(s < d)) return Fate::Escaped;
  st.pos = st.pos + s * st.dir;
  return st.orders >= rr.max_orders ? Fate::Capped : Fate::Flying;
}

// Random numbers of photon `photon`: Philox block `draw` of the stream
// (photon, row, purpose) under key `seed`.
struct PhotonStream {
  uint64_t seed;
  uint32_t row;
  uint32_t purpose;
  NEBULA_HD Uniform4 block(uint32_t photon, uint32_t draw) const {
    return philox_uniform4(seed, draw, photon, row, purpose);
  }
};

// Stream purposes keep tabulator and slab runs with equal seeds independent.
constexpr uint32_t kPurposeSphere = 0x5350u;  // "SP"
constexpr uint32_t kPurposeSlab = 0x534cu;    // "SL"

// Weights are tallied as 32.32 fixed point so that sums are exact and
// independent of summation order: the same result for any thread count or
// launch shape, on either backend. Callers keep x in [0, 2).
NEBULA_HD uint64_t to_fixed(float x) {
  return static_cast<uint64_t>(static_cast<double>(x) * 4294967296.0 + 0.5);
}
inline double from_fixed(uint64_t v) { return static_cast<double>(v) * (1.0 / 4294967296.0); }

}  // namespace nebula
