#include <cuda_runtime.h>

#include <string>

#include "core/cuda_check.h"
#include "core/device_mirror.h"
#include "core/error.h"
#include "core/gpu.h"

namespace nebula {

bool gpu_available(std::string* reason) {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    if (reason) *reason = std::string("no usable CUDA device: ") + cudaGetErrorString(status);
    cudaGetLastError();  // clear the sticky error so later queries start clean
    return false;
  }
  if (count == 0) {
    if (reason) *reason = "no CUDA device present";
    return false;
  }
  return true;
}

std::string gpu_description() {
  if (!gpu_available()) return "none";
  cudaDeviceProp prop{};
  int device = 0;
  cudaGetDevice(&device);
  cudaGetDeviceProperties(&prop, device);
  return std::string(prop.name) + " (" + std::to_string(prop.multiProcessorCount) + " SMs, sm_" +
         std::to_string(prop.major) + std::to_string(prop.minor) + ")";
}

// Unused in a CUDA build (no *_none.cpp entry point is compiled), kept so the
// declaration has one meaning in every build.
void DeviceMirror::download(void* host, size_t bytes) const {
  std::lock_guard<std::mutex> lock(mutex());
  if (device_ == nullptr || bytes_ != bytes) throw Error("device mirror: no device copy of that size to download");
  NEBULA_CUDA_CHECK(cudaMemcpy(host, device_, bytes, cudaMemcpyDeviceToHost));
}

void no_cuda_backend() { throw ParameterError("backend", "cuda: not available"); }

}  // namespace nebula
