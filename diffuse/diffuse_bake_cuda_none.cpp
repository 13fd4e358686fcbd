#include "core/gpu.h"
#include "diffuse/diffuse_bake.h"

namespace nebula {

std::vector<DiffusePassResult> diffuse_passes_cuda(const std::vector<DiffusePassInputs>&, const std::vector<double>&,
                                                   uint64_t, const GridShape&, const std::vector<DiffuseField*>&) {
  no_cuda_backend();
}

}  // namespace nebula
