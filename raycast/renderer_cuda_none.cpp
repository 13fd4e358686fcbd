#include "core/gpu.h"
#include "raycast/renderer.h"

namespace nebula {

Image render_cuda(const RenderInputs&, RenderStats*) { no_cuda_backend(); }

DiffuseLightArrays diffuse_light_arrays_cuda(const RenderInputs&) { no_cuda_backend(); }

double render_cuda_to_device(const RenderInputs&, float*, unsigned long long*) { no_cuda_backend(); }

}  // namespace nebula
