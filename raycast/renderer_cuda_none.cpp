#include "core/error.h"
#include "raycast/renderer.h"

namespace nebula {

Image render_cuda(const RenderInputs&, RenderStats*) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

}  // namespace nebula
