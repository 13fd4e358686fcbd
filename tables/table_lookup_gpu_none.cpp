#include "core/gpu.h"
#include "tables/table_lookup_gpu.h"

namespace nebula {

std::vector<float> lookup_batch_gpu(const ScatteringTable&, const std::vector<float>&, const std::vector<float>&,
                                    uint64_t*) {
  no_cuda_backend();
}

}  // namespace nebula
