#pragma once
#include <cstdint>

#include "core/hd.h"

namespace nebula {

// Philox4x32-10 (Salmon, Moraes, Dror & Shaw, "Parallel random numbers: as
// easy as 1, 2, 3", SC 2011). Counter-based: the output is a pure function of
// (counter, key), so photon i of row r draws the same numbers on any backend,
// thread count or launch shape.
struct U32x4 {
  uint32_t v0, v1, v2, v3;
};

NEBULA_HD void philox_mulhilo(uint32_t a, uint32_t b, uint32_t& hi, uint32_t& lo) {
#if NEBULA_ON_DEVICE
  lo = a * b;
  hi = __umulhi(a, b);
#else
  const uint64_t p = static_cast<uint64_t>(a) * b;
  lo = static_cast<uint32_t>(p);
  hi = static_cast<uint32_t>(p >> 32);
#endif
}

NEBULA_HD U32x4 philox4x32_10(U32x4 ctr, uint32_t k0, uint32_t k1) {
  constexpr uint32_t kMul0 = 0xD2511F53u, kMul1 = 0xCD9E8D57u;
  constexpr uint32_t kWeyl0 = 0x9E3779B9u, kWeyl1 = 0xBB67AE85u;
#if defined(__CUDACC__)
#pragma unroll
#endif
  for (int round = 0; round < 10; ++round) {
    uint32_t hi0, lo0, hi1, lo1;
    philox_mulhilo(kMul0, ctr.v0, hi0, lo0);
    philox_mulhilo(kMul1, ctr.v2, hi1, lo1);
    ctr = {hi1 ^ ctr.v1 ^ k0, lo1, hi0 ^ ctr.v3 ^ k1, lo0};
    k0 += kWeyl0;
    k1 += kWeyl1;
  }
  return ctr;
}

// Uniform float strictly inside (0, 1): (k + 1/2) 2^-23 with k the top 23
// bits. Every value is exact in float32, so 0 and 1 never occur and neither
// log(u) nor log(1 - u) can be infinite. The smallest value is 2^-24, which
// caps an exponential free path at 16.6 mean free paths (probability 6e-8).
NEBULA_HD float u32_to_open_unit(uint32_t x) {
  return static_cast<float>(x >> 9) * 0x1p-23f + 0x1p-24f;
}

struct Uniform4 {
  float u0, u1, u2, u3;
};

// Four uniforms for (counter word 0 = draw index, words 1..3 = stream), key = seed.
NEBULA_HD Uniform4 philox_uniform4(uint64_t seed, uint32_t draw, uint32_t s1, uint32_t s2,
                                   uint32_t s3) {
  const U32x4 r = philox4x32_10(U32x4{draw, s1, s2, s3}, static_cast<uint32_t>(seed),
                                static_cast<uint32_t>(seed >> 32));
  return {u32_to_open_unit(r.v0), u32_to_open_unit(r.v1), u32_to_open_unit(r.v2),
          u32_to_open_unit(r.v3)};
}

// A stream of uniforms: Philox blocks (draw, s1, s2, s3) under `seed`, the
// draw counter advancing, handed out four at a time. Which stream a path or
// photon uses is the caller's choice of (s1, s2, s3); the same numbers come
// on every backend and launch shape.
struct UniformStream {
  uint64_t seed;
  uint32_t s1, s2, s3;
  uint32_t draw = 0;
  int left = 0;
  Uniform4 buf{};
  NEBULA_HD UniformStream(uint64_t seed_, uint32_t s1_, uint32_t s2_, uint32_t s3_)
      : seed(seed_), s1(s1_), s2(s2_), s3(s3_) {}
  NEBULA_HD float next() {
    if (left == 0) {
      buf = philox_uniform4(seed, draw++, s1, s2, s3);
      left = 4;
    }
    const float v = left == 4 ? buf.u0 : (left == 3 ? buf.u1 : (left == 2 ? buf.u2 : buf.u3));
    --left;
    return v;
  }
};

}  // namespace nebula
