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
#include "core/cuda_side_stream.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "core/launch_order.h"
#include "illumination/star_pixels_cuda.h"

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
    axial_kernel(AxialMarchScene scene, Camera camera, LaunchTile first, float exposure, float* pixels,
                 unsigned long long* clamps) {
  // The tiles around the first tile first (core/launch_order.h).
  const int x = centre_out(int(blockIdx.x), first.x, int(gridDim.x)) * blockDim.x + threadIdx.x;
  const int y = centre_out(int(blockIdx.y), first.y, int(gridDim.y)) * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  const RayResult r = march_axial_ray<kMode, kStars, kField, kDeform>(scene, origin, dir);
  store_radiance(r, scene.n_bands, exposure, pixels, camera.width, camera.height, x, y);
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

// One thread per ray of the pixels at each star's image (illumination/star_pixels.h),
// each standing for its sub-cell, into sub; then stored per pixel from its cells.
template <AxialSkip kMode, AxialField kField, bool kDeform>
__global__ void __launch_bounds__(256) axial_star_pixel_kernel(AxialMarchScene scene, Camera camera,
                                                               const StarPixel* list, int n, int rays, float* sub,
                                                               unsigned long long* clamps) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= rays) return;
  const RayFootprint pixel = scene.footprint;
  const int n_clamps = march_star_pixel_ray(camera, list, n, rays, i, kMaxBands, sub,
                                            [&](Vec3 origin, Vec3 dir, float narrowing, float* out, size_t stride) {
    scene.footprint = sub_pixel_footprint(pixel, narrowing);
    const RayResult r = march_axial_ray<kMode, true, kField, kDeform>(scene, origin, dir);
    for (int b = 0; b < kMaxBands; ++b) out[size_t(b) * stride] = r.radiance[b];
    return r.table_clamps;
  });
  if (n_clamps) atomicAdd(clamps, static_cast<unsigned long long>(n_clamps));
}

thread_local SideStream star_pixel_stream;  // the star pixels' rays, beside the main launch

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
  const std::vector<Vec3> stars = star_positions(in.stars);
  const LaunchTile first = first_tile(in.camera, stars, bx, by);  // core/launch_order.h
  int rays = 0;
  const std::vector<StarPixel> list =
      scene.n_stars > 0 && in.star_pixels ? star_pixels(in.camera, stars, &rays)
                                          : std::vector<StarPixel>{};
  std::unique_ptr<DeviceArray<StarPixel>> device_list;
  std::unique_ptr<DeviceArray<float>> sub;
  if (!list.empty()) {
    device_list = std::make_unique<DeviceArray<StarPixel>>(list);
    sub = std::make_unique<DeviceArray<float>>(size_t(rays) * kMaxBands);
  }
  CudaEventTimer timer;
  dispatch_axial(scene.skip, scene.n_stars > 0, axial_field(scene), in.deform.any(),
                 [&](auto mode, auto has_stars, auto field, auto deform) {
    constexpr AxialSkip kMode = decltype(mode)::value;
    constexpr AxialField kField = decltype(field)::value;
    constexpr bool kDeform = decltype(deform)::value;
    if constexpr (decltype(has_stars)::value) {
      if (!list.empty()) {
        star_pixel_stream.start();
        axial_star_pixel_kernel<kMode, kField, kDeform><<<unsigned((rays + 255) / 256), 256, 0, star_pixel_stream.stream>>>(
            scene, in.camera, device_list->get(), int(list.size()), rays, sub->get(), clamps.get());
      }
    }
    axial_kernel<kMode, decltype(has_stars)::value, kField, kDeform>
        <<<grid, block>>>(scene, in.camera, first, in.exposure, pixels.get(), clamps.get());
    if (!list.empty()) {
      star_pixel_stream.join();
      store_star_pixels_cuda(device_list->get(), int(list.size()), sub->get(), rays, scene.n_bands, in.exposure,
                             pixels.get(), in.camera.width, in.camera.height);
    }
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
