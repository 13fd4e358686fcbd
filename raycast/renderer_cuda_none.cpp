#include "core/error.h"
#include "raycast/pyramid_render.h"
#include "raycast/renderer.h"

namespace nebula {

Image render_cuda(const RenderInputs&, RenderStats*) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

PyramidResult render_pyramid_cuda(const RenderInputs&, const PreparedPyramid&, bool) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

}  // namespace nebula
