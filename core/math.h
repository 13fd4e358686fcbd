#pragma once
#include <cmath>

#include "core/hd.h"

namespace nebula {

constexpr float kPi = 3.14159265358979323846f;
constexpr double kPiD = 3.14159265358979323846;
constexpr float kInv4Pi = 0.0795774715459476679f;

// Radius of the sphere with the volume of a unit cube: the voxel sphere of
// DESIGN.md (R = (3 / 4pi)^(1/3) l).
constexpr double kVoxelSphereRadius = 0.62035049089940001667;

template <class T>
NEBULA_HD T clamp(T v, T lo, T hi) {
  return v < lo ? lo : (v > hi ? hi : v);
}

// 1 / sqrt(x): the GPU's reciprocal square root (within 2 ulp), the CPU's
// quotient; for per-pair arithmetic in marchers that avoid divisions.
NEBULA_HD float reciprocal_sqrt(float x) {
#ifdef __CUDA_ARCH__
  return rsqrtf(x);
#else
  return 1.0f / sqrtf(x);
#endif
}

// 1 / x for 0 < |x| < 2^126: the GPU's reciprocal without IEEE rounding's
// Newton steps and slow-path test (within 2 ulp; the CUDA files are built
// without fast math, so 1.0f / x is a subroutine), the CPU's quotient.
NEBULA_HD float reciprocal(float x) {
#ifdef __CUDA_ARCH__
  return __fdividef(1.0f, x);
#else
  return 1.0f / x;
#endif
}

// e^x for the attenuation of light in the shading (x <= 0): the GPU's __expf
// (one ex2.approx; within 2 + floor(1.173 |x|) ulp, the CUDA Programming Guide's
// table of intrinsic functions; core_gpu_tests measures it), the CPU's expf.
// exp(0) = 1 exactly on both.
NEBULA_HD float fast_exp(float x) {
#ifdef __CUDA_ARCH__
  return __expf(x);
#else
  return expf(x);
#endif
}

}  // namespace nebula
