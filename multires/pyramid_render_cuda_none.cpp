#include "core/gpu.h"
#include "multires/pyramid_render.h"

namespace nebula {

PyramidResult render_pyramid_cuda(const RenderInputs&, const PreparedPyramid&, bool) { no_cuda_backend(); }

}  // namespace nebula
