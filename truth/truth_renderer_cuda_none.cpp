#include "core/error.h"
#include "validation/truth_renderer.h"

namespace nebula {

TruthOutput render_truth_cuda(const TruthInputs&) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

}  // namespace nebula
