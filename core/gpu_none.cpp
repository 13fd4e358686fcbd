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

void no_cuda_backend() { throw ParameterError("backend", std::string("cuda: ") + kNoCuda); }

}  // namespace nebula
