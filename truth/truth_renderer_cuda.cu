// CUDA launch of the path tracer: the path scene is assembled with a device
// placement (the density, majorant grid, emission and stars uploaded), then
// one thread per pixel runs the shared trace_pixel for all its samples.
#include <cuda_runtime.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "truth/truth_renderer.h"

namespace nebula {
namespace {

__global__ void truth_kernel(PathScene scene, Camera camera, float exposure, int spp, float* image, float* variance,
                             unsigned long long* counters) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  PathCounters c;
  float mean[kMaxBands], var[kMaxBands];
  trace_pixel(scene, camera, exposure, x, y, spp, mean, var, c);
  const size_t plane = size_t(camera.width) * camera.height, at = size_t(y) * camera.width + x;
  for (int b = 0; b < scene.n_bands; ++b) {
    image[b * plane + at] = mean[b];
    variance[b * plane + at] = var[b];
  }
  Vec3 o, d;
  atomicAdd(&counters[0], static_cast<unsigned long long>(c.vertices));
  atomicAdd(&counters[1], static_cast<unsigned long long>(c.tentative));
  if (c.capped) atomicAdd(&counters[2], static_cast<unsigned long long>(c.capped));
  if (camera.ray(x, y, o, d)) atomicAdd(&counters[3], 1ull);
}

}  // namespace

TruthOutput render_truth_cuda(const TruthInputs& in) {
  validate(in);
  const MajorantGrid majorant = build_majorant_grid(*in.density, in.majorant_block);
  DevicePlacement device;
  const PathScene scene = assemble_path_scene(in, majorant, device);
  TruthOutput out;
  out.image = Image(in.camera.width, in.camera.height, band_names(in.bands));
  out.variance = Image(in.camera.width, in.camera.height, band_names(in.bands));
  DeviceArray<float> image(out.image.pixels.size()), variance(out.variance.pixels.size());
  DeviceArray<unsigned long long> counters(4);
  const dim3 block(16, 8), grid((in.camera.width + 15) / 16, (in.camera.height + 7) / 8);
  CudaEventTimer timer;
  truth_kernel<<<grid, block>>>(scene, in.camera, in.exposure, in.spp, image.get(), variance.get(), counters.get());
  NEBULA_CUDA_CHECK(cudaGetLastError());
  out.seconds = timer.seconds();
  image.download(out.image.pixels.data());
  variance.download(out.variance.pixels.data());
  unsigned long long c[4] = {};
  counters.download(c);
  out.counters.vertices = c[0];
  out.counters.tentative = c[1];
  out.counters.capped = c[2];
  out.paths = uint64_t(c[3]) * uint64_t(in.spp) * in.bands.size();
  return out;
}

}  // namespace nebula
