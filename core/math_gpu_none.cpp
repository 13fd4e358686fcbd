#include "core/gpu.h"
#include "core/math_gpu.h"

namespace nebula {

std::vector<float> fast_math_gpu(FastMath, const std::vector<float>&) { no_cuda_backend(); }

}  // namespace nebula
