#include "core/gpu.h"
#include "truth/truth_renderer.h"

namespace nebula {

TruthOutput render_truth_cuda(const TruthInputs&) { no_cuda_backend(); }

}  // namespace nebula
