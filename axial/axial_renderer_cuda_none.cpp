#include "core/error.h"
#include "raycast/axial_renderer.h"

namespace nebula {

Image render_axial_cuda(const AxialRenderInputs&, AxialRenderStats*) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

}  // namespace nebula
