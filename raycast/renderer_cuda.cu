// CUDA launch of the ray marcher: the scene is assembled with a device
// placement (raycast/march_scene.h: the grids, tables and baked depths
// uploaded), then one thread per pixel runs the shared march_ray.
#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_side_stream.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "core/frame_pool.h"
#include "raycast/diffuse_light.h"
#include "raycast/host_copy.h"
#include "raycast/march_scene.h"
#include "raycast/renderer.h"
#include "illumination/star_pixels_cuda.h"
#include "raycast/voxel_sources.h"

namespace nebula {
namespace {

// Blocks of 256 threads per SM the compiler must fit in registers (exact
// mode). With the band loops unrolled (per-band arrays in registers, not on
// the stack) and at most 64 registers: 4.69 ms against 5.79 ms per frame on an
// H100 (docs/performance.md, before the chord irradiance; 5.03 ms with it);
// with the diffuse field's terms, 6.85 ms (6.72 ms against 6.96 ms at 80
// registers before the chord irradiance). The smooth mode keeps its 116 registers.
#ifndef NEBULA_RENDER_MIN_BLOCKS
#define NEBULA_RENDER_MIN_BLOCKS 4
#endif

// Blocks of 256 threads per SM for the field's per-voxel light: 4 holds it to
// 64 registers. With zonal degrees the compiler took 128 (22% occupancy,
// latency-bound): the 1080p frame with them went 8.91-8.93 ms -> 8.40-8.41 ms
// (H100; 3, 5, 6 and 8 blocks: 8.53, 8.76, 9.14 and 10.36 ms); without zonal
// degrees the frame did not change (docs/performance.md).
#ifndef NEBULA_DIFFUSE_LIGHT_MIN_BLOCKS
#define NEBULA_DIFFUSE_LIGHT_MIN_BLOCKS 4
#endif
// The zonal kernel: blocks of 128, 7 per SM, so 72 registers (8 bytes
// spilled; 64 registers spilled 20 and were L1-bound on the spills, 80 left
// 24 warps an SM): the zonal 1080p frame 6.974-6.976 ms against 7.006-7.017
// (256 x 4) and 7.081-7.087 (256 x 3) on an H200 (docs/performance.md).
#ifndef NEBULA_DIFFUSE_ZONAL_MIN_BLOCKS
#define NEBULA_DIFFUSE_ZONAL_MIN_BLOCKS 7
#endif
#ifndef NEBULA_DIFFUSE_ZONAL_BLOCK
#define NEBULA_DIFFUSE_ZONAL_BLOCK 128
#endif

// Threads per block of the per-view pass.
template <bool kZonal>
constexpr int kDiffuseLightBlock = kZonal ? NEBULA_DIFFUSE_ZONAL_BLOCK : 256;

// One thread per voxel: the diffuse field's light towards this view's eye
// (raycast/diffuse_light.h).
template <int kDeg, bool kZonal>
__global__ void __launch_bounds__(kDiffuseLightBlock<kZonal>,
                                  kZonal ? NEBULA_DIFFUSE_ZONAL_MIN_BLOCKS : NEBULA_DIFFUSE_LIGHT_MIN_BLOCKS)
    diffuse_light_kernel(MarchScene scene, Camera camera, DiffuseLightPlanes out) {
  const GridShape& g = scene.density.shape;
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= g.count()) return;
  const int x = int(i % size_t(g.nx)), y = int(i / size_t(g.nx) % size_t(g.ny)), z = int(i / (size_t(g.nx) * g.ny));
  diffuse_light_row<kDeg, kZonal>(scene, camera, y, z, x, x + 1, out);
}

// One thread per voxel: the preview's light of each voxel towards this view's
// eye (raycast/voxel_sources.h).
template <int kDeg, bool kZonal>
__global__ void voxel_source_kernel(MarchScene scene, Camera camera, VoxelSourcePlanes out,
                                    unsigned long long* clamps) {
  const GridShape& g = scene.density.shape;
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= g.count()) return;
  const int x = int(i % size_t(g.nx)), y = int(i / size_t(g.nx) % size_t(g.ny)), z = int(i / (size_t(g.nx) * g.ny));
  const int n = voxel_source_row<kDeg, kZonal>(scene, camera, y, z, x, x + 1, out);
  if (n) atomicAdd(clamps, static_cast<unsigned long long>(n));
}

// Which rays a launch marches: all of them, or the exact traversal's split at
// passes_near_a_star (raycast/ray_march.h): the far ones with the star's phase
// at each chord's half-light point, the few near ones in a second launch that
// averages it over the chords' angles. The split keeps that averaging out of
// the main kernel's registers; the image is the CPU loop's.
enum class RaySet { All, Far, Near };

template <bool kSmooth, bool kDiffuse, bool kVoxelSources, bool kZonal, RaySet kRays>
__global__ void __launch_bounds__(256, kSmooth ? 2 : NEBULA_RENDER_MIN_BLOCKS)
    render_kernel(MarchScene scene, Camera camera, MarchMode mode, float exposure, float* pixels,
                  unsigned long long* clamps) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  if constexpr (kRays != RaySet::All)
    if (passes_near_a_star(scene, origin, dir) != (kRays == RaySet::Near)) return;
  const RayResult r =
      march_ray<kSmooth, kDiffuse, kVoxelSources, kZonal, kRays == RaySet::Near>(scene, origin, dir, mode);
  store_radiance(r, scene.n_bands, exposure, pixels, camera.width, camera.height, x, y);
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

// One thread per ray of the pixels at each star's image (illumination/star_pixels.h),
// each ray standing for its sub-cell, into sub (kMaxBands per ray); the
// store (illumination/star_pixels_cuda.h) then sums each pixel's cells. Launched on
// the near rays' side stream, beside the main launch.
template <bool kDiffuse, bool kZonal>
__global__ void __launch_bounds__(256) star_pixel_kernel(MarchScene scene, Camera camera, MarchMode mode,
                                                         const StarPixel* list, int n, int rays, float* sub,
                                                         unsigned long long* clamps) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= rays) return;
  const RayFootprint pixel = scene.footprint;
  const int n_clamps = march_star_pixel_ray(camera, list, n, rays, i, kMaxBands, sub,
                                            [&](Vec3 origin, Vec3 dir, float narrowing, float* out, size_t stride) {
    scene.footprint = sub_pixel_footprint(pixel, narrowing);
    const RayResult r = march_ray<false, kDiffuse, false, kZonal, true>(scene, origin, dir, mode);
    for (int b = 0; b < kMaxBands; ++b) out[size_t(b) * stride] = r.radiance[b];
    return r.table_clamps;
  });
  if (n_clamps) atomicAdd(clamps, static_cast<unsigned long long>(n_clamps));
}

// A device array kept per thread and reused while the size asked for fits:
// frames of an animation or a viewer allocate nothing. A fresh allocation and
// release of a frame's buffers (25 MB for 1080p in 3 bands, 64 MB per band of
// the field's light at 256^3) cost more than the march itself.
template <class T>
T* reused(std::unique_ptr<DeviceArray<T>>& slot, size_t n) {
  if (!slot || slot->size() < n) {
    slot.reset();
    slot = std::make_unique<DeviceArray<T>>(n);
  }
  return slot->get();
}
// Page-locked host memory for a frame's download: the copy engine writes it at
// the bus's speed (a pageable destination is staged by the driver at about a
// third of it), then every core copies it into the frame.
struct PinnedStaging {
  float* data = nullptr;
  size_t size = 0;
  float* get(size_t n) {
    if (n > size) {
      if (data) cudaFreeHost(data);
      data = nullptr;
      size = 0;
      NEBULA_CUDA_CHECK(cudaMallocHost(&data, n * sizeof(float)));
      size = n;
    }
    return data;
  }
  ~PinnedStaging() {
    if (data) cudaFreeHost(data);
  }
};
struct FrameBuffers {
  std::unique_ptr<DeviceArray<float>> pixels, light[kMaxBands], peak[kMaxBands];
  std::unique_ptr<DeviceArray<unsigned long long>> clamps;
  std::unique_ptr<DeviceArray<StarPixel>> star_pixels;
  std::unique_ptr<DeviceArray<float>> star_rays;
  PinnedStaging staging;
  SideStream near;
  SideStream star_rays_stream;  // the star pixels' rays: their own stream, so they run beside both march launches
};
thread_local FrameBuffers frame_buffers;

}  // namespace

double render_cuda_to_device(const RenderInputs& in, float* pixels, unsigned long long* clamps) {
  DevicePlacement device;
  MarchScene scene = assemble_march_scene(in, device);
  const dim3 block(16, 16), grid((in.camera.width + 15) / 16, (in.camera.height + 15) / 16);
  const size_t count = scene.density.shape.count();
  const unsigned voxel_blocks = static_cast<unsigned>((count + 255) / 256);
  // The star pixels' list, on the device before the frame's first launch: a copy after
  // it would hold the host until the per-view pass ends, and the march's launches with it.
  int star_rays = 0;
  const std::vector<StarPixel> star_list = marches_star_pixels(in)
                                               ? star_pixels(in.camera, star_positions(in.stars), &star_rays)
                                               : std::vector<StarPixel>{};
  StarPixel* device_list = nullptr;
  float* star_sub = nullptr;
  if (!star_list.empty()) {
    device_list = reused(frame_buffers.star_pixels, star_list.size());
    NEBULA_CUDA_CHECK(
        cudaMemcpy(device_list, star_list.data(), star_list.size() * sizeof(StarPixel), cudaMemcpyHostToDevice));
    star_sub = reused(frame_buffers.star_rays, size_t(star_rays) * kMaxBands);
  }
  CudaEventTimer timer;
  if (in.mode.voxel_sources) {
    // The preview: every voxel's light towards the eye, once (raycast/voxel_sources.h).
    VoxelSourcePlanes sources;
    for (int b = 0; b < scene.n_bands; ++b) {
      sources.band[b] = reused(frame_buffers.light[b], count);
      scene.voxel_source[b] = sources.band[b];
      if (scene.has_diffuse && scene.diffuse.has[b]) {
        sources.peak[b] = reused(frame_buffers.peak[b], count);
        scene.diffuse_peak[b] = sources.peak[b];
      }
    }
    dispatch_source_degree(scene, [&](auto degree) {
      dispatch_zonal(scene, [&](auto zonal) {
        voxel_source_kernel<degree(), zonal()><<<voxel_blocks, 256>>>(scene, in.camera, sources, clamps);
      });
    });
    NEBULA_CUDA_CHECK(cudaGetLastError());
  } else if (scene.has_diffuse) {
    // The diffuse field's light for this view, per band with a field (every
    // voxel written by the kernel).
    DiffuseLightPlanes planes;
    for (int b = 0; b < scene.n_bands; ++b)
      if (scene.diffuse.has[b]) {
        planes.band[b] = reused(frame_buffers.light[b], count);
        planes.peak[b] = reused(frame_buffers.peak[b], count);
        scene.diffuse_light[b] = planes.band[b];
        scene.diffuse_peak[b] = planes.peak[b];
      }
    dispatch_diffuse_degree(scene.diffuse.degree, [&](auto degree) {
      dispatch_zonal(scene, [&](auto zonal) {
        constexpr int threads = kDiffuseLightBlock<zonal()>;
        diffuse_light_kernel<degree(), zonal()>
            <<<unsigned((count + threads - 1) / threads), threads>>>(scene, in.camera, planes);
      });
    });
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  // One kernel per mode (raycast/ray_march.h, dispatch_march).
  dispatch_march(scene, in.mode, [&](auto smooth, auto diffuse, auto voxel_sources, auto zonal) {
    if constexpr (!smooth() && !voxel_sources()) {
      if (scene.n_stars > 0) {
        // The star pixels' rays first, on a stream of their own: the longest rays of the
        // frame (the densest cells, next to the star), so they start at once and end
        // beside the main launch instead of after the near rays.
        SideStream& star_side = frame_buffers.star_rays_stream;
        if (!star_list.empty()) {
          star_side.start();
          star_pixel_kernel<diffuse(), zonal()><<<unsigned((star_rays + 255) / 256), 256, 0, star_side.stream>>>(
              scene, in.camera, in.mode, device_list, int(star_list.size()), star_rays, star_sub, clamps);
        }
        SideStream& side = frame_buffers.near;
        side.start();
        render_kernel<false, diffuse(), false, zonal(), RaySet::Near>
            <<<grid, block, 0, side.stream>>>(scene, in.camera, in.mode, in.exposure, pixels, clamps);
        render_kernel<false, diffuse(), false, zonal(), RaySet::Far>
            <<<grid, block>>>(scene, in.camera, in.mode, in.exposure, pixels, clamps);
        side.join();
        // After every launch: the star pixels replace their single rays.
        if (!star_list.empty()) {
          star_side.join();
          store_star_pixels_cuda(device_list, int(star_list.size()), star_sub, star_rays, scene.n_bands, in.exposure,
                                 pixels, in.camera.width, in.camera.height);
        }
        return;
      }
    }
    render_kernel<smooth(), diffuse(), voxel_sources(), zonal(), RaySet::All>
        <<<grid, block>>>(scene, in.camera, in.mode, in.exposure, pixels, clamps);
  });
  NEBULA_CUDA_CHECK(cudaGetLastError());
  return timer.seconds();
}

DiffuseLightArrays diffuse_light_arrays_cuda(const RenderInputs& in) {
  DevicePlacement device;
  MarchScene scene = assemble_march_scene(in, device);
  const size_t count = scene.density.shape.count();
  DiffuseLightPlanes planes;
  DiffuseLightArrays out;
  out.light.resize(in.bands.size());
  out.peak.resize(in.bands.size());
  out.device_light.resize(in.bands.size());
  out.device_peak.resize(in.bands.size());
  // Device arrays the result's mirrors own (its host arrays stay empty).
  const auto made = [&](DeviceMirror& mirror) {
    auto array = std::make_shared<DeviceArray<float>>(count);
    mirror.set({array, array->get()}, array->bytes());
    return array->get();
  };
  for (int b = 0; b < scene.n_bands; ++b)
    if (scene.diffuse.has[b]) {
      planes.band[b] = made(out.device_light[size_t(b)]);
      planes.peak[b] = made(out.device_peak[size_t(b)]);
    }
  dispatch_diffuse_degree(scene.diffuse.degree, [&](auto degree) {
    dispatch_zonal(scene, [&](auto zonal) {
      constexpr int threads = kDiffuseLightBlock<zonal()>;
      diffuse_light_kernel<degree(), zonal()>
          <<<unsigned((count + threads - 1) / threads), threads>>>(scene, in.camera, planes);
    });
  });
  NEBULA_CUDA_CHECK(cudaGetLastError());
  return out;
}

Image render_cuda(const RenderInputs& in, RenderStats* stats) {
  // Every pixel is downloaded below: the memory of a recycled frame will do.
  Image image = take_frame_image(in.camera.width, in.camera.height, band_names(in.bands));
  // Pixels a camera does not see (outside a fisheye's circle) stay 0: cleared each frame.
  float* pixels = reused(frame_buffers.pixels, image.pixels.size());
  unsigned long long* clamps = reused(frame_buffers.clamps, 1);
  NEBULA_CUDA_CHECK(cudaMemset(pixels, 0, image.pixels.size() * sizeof(float)));
  NEBULA_CUDA_CHECK(cudaMemset(clamps, 0, sizeof(unsigned long long)));
  const double seconds = render_cuda_to_device(in, pixels, clamps);
  float* staging = frame_buffers.staging.get(image.pixels.size());
  NEBULA_CUDA_CHECK(cudaMemcpy(staging, pixels, image.pixels.size() * sizeof(float), cudaMemcpyDeviceToHost));
  parallel_copy(image.pixels.data(), staging, image.pixels.size());
  if (stats) {
    unsigned long long count = 0;
    NEBULA_CUDA_CHECK(cudaMemcpy(&count, clamps, sizeof count, cudaMemcpyDeviceToHost));
    stats->seconds = seconds;
    stats->table_clamps = count;
  }
  return image;
}

}  // namespace nebula
