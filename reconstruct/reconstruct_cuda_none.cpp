#include "core/gpu.h"
#include "reconstruct/projection.h"
#include "reconstruct/reconstruct.h"

namespace nebula {

std::vector<float> powell_columns_cuda(const ColumnProjection&, const std::vector<float>&, int, const PowellSettings&,
                                       long long*) {
  no_cuda_backend();
}

}  // namespace nebula
