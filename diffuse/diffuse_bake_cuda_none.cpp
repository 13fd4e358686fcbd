#include "core/gpu.h"
#include "diffuse/diffuse_bake.h"

namespace nebula {

DiffusePassResult diffuse_pass_cuda(const DiffusePassInputs&, uint64_t) { no_cuda_backend(); }

}  // namespace nebula
