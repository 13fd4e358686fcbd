#include "core/gpu.h"
#include "spectral/spectral_renderer.h"

namespace nebula::spectral {

Image render_spectral_cuda(const SpectralRenderInputs&, double*) { no_cuda_backend(); }

}  // namespace nebula::spectral
