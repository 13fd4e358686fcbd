// CUDA launch of the ray marcher: the scene is assembled with a device
// placement (raycast/march_scene.h: the grids, tables and baked depths
// uploaded), then one thread per pixel runs the shared march_ray.
#include <cuda_runtime.h>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "raycast/march_scene.h"
#include "raycast/renderer.h"

namespace nebula {
namespace {

// Blocks of 256 threads per SM the compiler must fit in registers (exact
// mode). With the band loops unrolled (per-band arrays in registers, not on
// the stack) and at most 64 registers: 4.69 ms against 5.79 ms per frame on an
// H100 (docs/performance.md). The smooth mode keeps its 116 registers.
#ifndef NEBULA_RENDER_MIN_BLOCKS
#define NEBULA_RENDER_MIN_BLOCKS 4
#endif

template <bool kSmooth>
__global__ void __launch_bounds__(256, kSmooth ? 2 : NEBULA_RENDER_MIN_BLOCKS) render_kernel(MarchScene scene, Camera camera, MarchMode mode, float exposure,
                              float* pixels, unsigned long long* clamps) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  const RayResult r = march_ray_in_mode<kSmooth>(scene, origin, dir, mode);
  store_radiance(r, scene.n_bands, exposure, pixels, camera.width, camera.height, x, y);
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

}  // namespace

double render_cuda_to_device(const RenderInputs& in, float* pixels, unsigned long long* clamps) {
  DevicePlacement device;
  const MarchScene scene = assemble_march_scene(in, device);
  const dim3 block(16, 16), grid((in.camera.width + 15) / 16, (in.camera.height + 15) / 16);
  CudaEventTimer timer;
  // One kernel per mode: the exact one carries none of the smooth mode's code.
  if (in.mode.step_voxels > 0.0f)
    render_kernel<true><<<grid, block>>>(scene, in.camera, in.mode, in.exposure, pixels, clamps);
  else
    render_kernel<false><<<grid, block>>>(scene, in.camera, in.mode, in.exposure, pixels, clamps);
  NEBULA_CUDA_CHECK(cudaGetLastError());
  return timer.seconds();
}

Image render_cuda(const RenderInputs& in, RenderStats* stats) {
  Image image(in.camera.width, in.camera.height, band_names(in.bands));
  DeviceArray<float> pixels(image.pixels.size());
  DeviceArray<unsigned long long> clamps(1);
  const double seconds = render_cuda_to_device(in, pixels.get(), clamps.get());
  pixels.download(image.pixels.data());
  if (stats) {
    unsigned long long count = 0;
    clamps.download(&count);
    stats->seconds = seconds;
    stats->table_clamps = count;
  }
  return image;
}

}  // namespace nebula
