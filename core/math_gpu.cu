#include <cuda_runtime.h>

#include "core/cuda_check.h"
#include "core/device_array.h"
#include "core/math.h"
#include "core/math_gpu.h"

namespace nebula {
namespace {

__global__ void fast_math_kernel(FastMath f, const float* x, float* y, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  switch (f) {
    case FastMath::Reciprocal: y[i] = reciprocal(x[i]); break;
    case FastMath::ReciprocalSqrt: y[i] = reciprocal_sqrt(x[i]); break;
    case FastMath::Exp: y[i] = fast_exp(x[i]); break;
  }
}

}  // namespace

std::vector<float> fast_math_gpu(FastMath f, const std::vector<float>& x) {
  if (x.empty()) return {};
  DeviceArray<float> in(x), out(x.size());
  const int n = static_cast<int>(x.size());
  fast_math_kernel<<<(n + 255) / 256, 256>>>(f, in.get(), out.get(), n);
  NEBULA_CUDA_CHECK(cudaGetLastError());
  std::vector<float> y(x.size());
  out.download(y.data());
  return y;
}

}  // namespace nebula
