#pragma once
#include <string>

namespace nebula {

// Whether a CUDA device can run our kernels here. When not, `reason` says why
// (built without CUDA, no device, driver error) so callers can say so.
bool gpu_available(std::string* reason = nullptr);

// One line naming the device, e.g. "NVIDIA H100 80GB HBM3 (132 SMs, sm_90)".
std::string gpu_description();

// What every CUDA entry point of a build without CUDA does: throws
// ParameterError("backend", ...) saying so.
[[noreturn]] void no_cuda_backend();

}  // namespace nebula
