// Stand-ins for the CUDA backend in builds without CUDA.
#include "core/gpu.h"
#include "montecarlo/slab.h"
#include "montecarlo/tabulate.h"

namespace nebula {

SphereTallies tabulate_sphere_cuda(const TabulateParams&, Progress*) { no_cuda_backend(); }

SlabTallies simulate_slab_cuda(const SlabParams&, Progress*) { no_cuda_backend(); }

}  // namespace nebula
