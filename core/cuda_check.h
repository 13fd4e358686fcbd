#pragma once
// Host-side checking of CUDA runtime calls; include only from .cu files.
#include <cuda_runtime.h>

#include <string>

#include "core/error.h"

namespace nebula {

inline void cuda_check(cudaError_t status, const char* what) {
  if (status != cudaSuccess)
    throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}

}  // namespace nebula

#define NEBULA_CUDA_CHECK(call) ::nebula::cuda_check((call), #call)
