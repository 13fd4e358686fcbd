#pragma once
// GPU time of the work queued between construction and seconds(), measured
// with CUDA events (host clocks would time the launch, not the kernels).
// Include only from .cu files.
#include <cuda_runtime.h>

#include "core/cuda_check.h"

namespace nebula {

class CudaEventTimer {
 public:
  CudaEventTimer() {
    NEBULA_CUDA_CHECK(cudaEventCreate(&start_));
    NEBULA_CUDA_CHECK(cudaEventCreate(&stop_));
    NEBULA_CUDA_CHECK(cudaEventRecord(start_));
  }
  ~CudaEventTimer() {
    cudaEventDestroy(start_);
    cudaEventDestroy(stop_);
  }
  CudaEventTimer(const CudaEventTimer&) = delete;
  CudaEventTimer& operator=(const CudaEventTimer&) = delete;

  // Waits for the queued work and returns its duration.
  double seconds() {
    NEBULA_CUDA_CHECK(cudaEventRecord(stop_));
    NEBULA_CUDA_CHECK(cudaEventSynchronize(stop_));
    float ms = 0;
    NEBULA_CUDA_CHECK(cudaEventElapsedTime(&ms, start_, stop_));
    return ms * 1e-3;
  }

 private:
  cudaEvent_t start_ = nullptr, stop_ = nullptr;
};

}  // namespace nebula
