#include "core/device_mirror.h"
#include "core/error.h"
#include "core/gpu.h"

namespace nebula {

namespace {
constexpr const char* kNoCuda = "this build has no CUDA backend (configured without a CUDA compiler)";
}  // namespace

bool gpu_available(std::string* reason) {
  if (reason) *reason = kNoCuda;
  return false;
}

std::string gpu_description() { return "none (built without CUDA)"; }

void DeviceMirror::download(void*, size_t) const {
  throw Error("device mirror: this build has no CUDA backend");
}

void no_cuda_backend() { throw ParameterError("backend", std::string("cuda: ") + kNoCuda); }

}  // namespace nebula
