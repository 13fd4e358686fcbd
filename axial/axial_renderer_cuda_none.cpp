#include "axial/axial_renderer.h"
#include "core/gpu.h"

namespace nebula {

Image render_axial_cuda(const AxialRenderInputs&, AxialRenderStats*) { no_cuda_backend(); }

}  // namespace nebula
