// Stand-ins for the CUDA backend in builds without CUDA.
#include "core/error.h"
#include "montecarlo/slab.h"
#include "montecarlo/tabulate.h"

namespace nebula {

SphereTallies tabulate_sphere_cuda(const TabulateParams&, Progress*) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

SlabTallies simulate_slab_cuda(const SlabParams&, Progress*) {
  throw Error("--backend cuda: this build has no CUDA backend (configured without a CUDA compiler)");
}

}  // namespace nebula
