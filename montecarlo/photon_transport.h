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
  uint32_t draw = 0;        // Philox blocks used; 0 means the photon is not yet emitted
  int orders = 0;           // scatterings so far
  NEBULA_HD float weight() const { return weight_forced * weight_albedo; }
};

enum class Fate : int {
  Flying = 0,    // at an interaction point, to be scattered by the next step
  Escaped,       // left after at least one scattering
  Unscattered,   // left without scattering (analog sampling, or tau = 0)
  Absorbed,      // ended by Russian roulette
  Capped,        // reached the order cap
};

// One step of a photon, the same on every backend: a photon not yet emitted
// is placed by the source, any other scatters where it stands; then it flies
// to its next interaction or out. Every step uses exactly one Philox block
// (u0 polar angle or beam radius, u1 azimuth, u2 free path, u3 roulette) and
// runs one shared path through sin/cos, the exit distance and the logarithm,
// so the lanes of a GPU warp stay together whatever their photon is doing.
// `unscattered` receives the weight that leaves without scattering.
template <class Geometry, class Source>
NEBULA_HD Fate transport_step(const Geometry& geometry, const Medium& m, const Roulette& rr,
                              const Source& source, bool forced, const Uniform4& u,
                              PhotonState& st, float& unscattered) {
  float sin_phi, cos_phi;
  sin_cos_2pi(u.u1, sin_phi, cos_phi);
  const bool emitted_now = st.draw == 0;
  ++st.draw;
  unscattered = 0.0f;
  if (emitted_now) {
    source.emit(u.u0, sin_phi, cos_phi, st);
    st.weight_forced = 1.0f;
    st.weight_albedo = 1.0f;
    st.orders = 0;
  } else {
    st.weight_albedo *= m.albedo;
    st.dir = scatter_direction(st.dir, hg_sample(m.g, u.u0), sin_phi, cos_phi);
    ++st.orders;
    if (st.weight_albedo < rr.threshold) {
      if (u.u3 >= rr.survival) return Fate::Absorbed;
      st.weight_albedo /= rr.survival;
    }
  }
  const float d = geometry.exit_distance(st.pos, st.dir);
  // Free path from exp(-sigma s), truncated to the chord on a forced first flight.
  float truncation = 1.0f;
  if (emitted_now && forced) {
    const float optical = m.sigma_ext * d;
    truncation = -expm1f(-optical);  // probability of interacting before the exit
    if (!(truncation > 0.0f)) {
      unscattered = 1.0f;
      return Fate::Unscattered;
    }
    unscattered = expf(-optical);
    st.weight_forced = truncation;
  }
  const float s = -log1pf(-u.u2 * truncation) / m.sigma_ext;
  if (!(s < d)) {
    if (st.orders > 0) return Fate::Escaped;
    unscattered = 1.0f;
    return Fate::Unscattered;
  }
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
