// CUDA launch of the axial marcher: the scene is assembled with a device
// placement (axial_scene.h: the map, its skip structures, the baked depths and
// the tables uploaded), then one thread per pixel runs the shared
// march_axial_ray.
#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "axial/axial_renderer.h"
#include "axial/axial_scene.h"
#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"

namespace nebula {
namespace {

// Blocks of 256 threads per SM the compiler must fit in registers (the launch uses blocks of
// 128, below: the same register budget, 6 of them).
#ifndef NEBULA_AXIAL_MIN_BLOCKS
#define NEBULA_AXIAL_MIN_BLOCKS 3  // with the band loops unrolled, at most 80 registers: 15-35% faster (H100, docs/performance.md)
#endif

// One instantiation per skip mode, star use, diffuse field kind and deformation use: each kernel holds only its
// mode's checks and gets its own register allocation; the physics is the
// same template.
template <AxialSkip kMode, bool kStars, AxialField kField, bool kDeform>
__global__ void __launch_bounds__(256, NEBULA_AXIAL_MIN_BLOCKS)
    axial_kernel(AxialMarchScene scene, Camera camera, float exposure, float* pixels, unsigned long long* clamps) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  const RayResult r = march_axial_ray<kMode, kStars, kField, kDeform>(scene, origin, dir);
  store_radiance(r, scene.n_bands, exposure, pixels, camera.width, camera.height, x, y);
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

}  // namespace

Image render_axial_cuda(const AxialRenderInputs& in, AxialRenderStats* stats) {
  DevicePlacement device;
  const AxialMarchScene scene = assemble_axial_scene(in, device);
  Image image(in.camera.width, in.camera.height, band_names(in.bands));
  DeviceArray<float> pixels(image.pixels.size());
  DeviceArray<unsigned long long> clamps(1);
  // Blocks of 8 x 16 rays: a block holds its multiprocessor slot until its slowest warp ends,
  // and skipping makes the rays' work very uneven, so smaller blocks waste less. Faster than
  // 16 x 16 in every mode measured (H100: distance 5-14%, the naive march 1-9%; docs/performance.md).
#ifndef NEBULA_AXIAL_BLOCK_X
#define NEBULA_AXIAL_BLOCK_X 8
#endif
  constexpr int bx = NEBULA_AXIAL_BLOCK_X, by = 128 / bx;
  const dim3 block(bx, by), grid((in.camera.width + bx - 1) / bx, (in.camera.height + by - 1) / by);
  CudaEventTimer timer;
  dispatch_axial(scene.skip, scene.n_stars > 0, axial_field(scene), in.deform.any(),
                 [&](auto mode, auto has_stars, auto field, auto deform) {
    axial_kernel<decltype(mode)::value, decltype(has_stars)::value, decltype(field)::value, decltype(deform)::value>
        <<<grid, block>>>(scene, in.camera, in.exposure, pixels.get(), clamps.get());
  });
  NEBULA_CUDA_CHECK(cudaGetLastError());
  const double seconds = timer.seconds();
  pixels.download(image.pixels.data());
  unsigned long long clamp_count = 0;
  clamps.download(&clamp_count);
  if (stats) {
    stats->seconds = seconds;
    stats->table_clamps = clamp_count;
    stats->device_bytes = device.bytes();
    stats->skip_used = scene.skip;
  }
  return image;
}

}  // namespace nebula
