#include "core/gpu.h"

namespace nebula {

bool gpu_available(std::string* reason) {
  if (reason) *reason = "this build has no CUDA backend (configured without a CUDA compiler)";
  return false;
}

std::string gpu_description() { return "none (built without CUDA)"; }

}  // namespace nebula
