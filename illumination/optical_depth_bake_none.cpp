#include "core/error.h"
#include "illumination/optical_depth_bake.h"

namespace nebula {

BakeResult bake_star_depths_cuda(const DensityGrid&, const std::vector<Vec3>&) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

}  // namespace nebula
