#include "core/gpu.h"
#include "illumination/optical_depth_bake.h"

namespace nebula {

BakeResult bake_star_depths_cuda(const DensityGrid&, const std::vector<Vec3>&) { no_cuda_backend(); }

}  // namespace nebula
