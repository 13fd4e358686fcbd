#pragma once
// The fast functions of core/math.h evaluated on the device, so that tests can
// measure their error where it arises (the host computes the IEEE quotients).
#include <vector>

namespace nebula {

enum class FastMath { Reciprocal, ReciprocalSqrt, Exp };

// f(x) for every x, computed by a CUDA kernel with the same NEBULA_HD code the
// marchers call; throws ParameterError("backend", ...) in a build without CUDA.
std::vector<float> fast_math_gpu(FastMath f, const std::vector<float>& x);

}  // namespace nebula
