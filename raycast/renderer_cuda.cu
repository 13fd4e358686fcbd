// CUDA launch of the ray marcher: uploads the grids, tables and baked depths,
// then one thread per pixel runs the shared march_ray.
#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/device_array.h"
#include "core/cuda_timer.h"
#include "multires/pyramid_pixels.h"
#include "raycast/pyramid_render.h"
#include "raycast/renderer.h"
#include "tables/device_table.h"

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
  const size_t plane = size_t(camera.width) * camera.height;
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < scene.n_bands) pixels[b * plane + size_t(y) * camera.width + x] = exposure * r.radiance[b];
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

// Everything one render reads, uploaded; the MarchScene points into it.
class DeviceScene {
 public:
  explicit DeviceScene(const RenderInputs& in) : density_(in.density->tau_v) {
    validate(in);
    scene_.density = {in.density->shape, density_.get()};
    scene_.n_bands = static_cast<int>(in.bands.size());
    scene_.min_transmittance = in.min_transmittance;
    for (int b = 0; b < scene_.n_bands; ++b) {
      const RenderBand& band = in.bands[b];
      scene_.extinction_ratio[b] = band.extinction_ratio;
      scene_.albedo[b] = band.albedo;
      scene_.table[b] = TableView{};
      if (band.table) {
        tables_.push_back(std::make_unique<DeviceTable>(*band.table));
        scene_.table[b] = tables_.back()->view();
      }
      scene_.emission[b] = nullptr;
      if (band.emission) {
        buffers_.push_back(std::make_unique<DeviceArray<float>>(*band.emission));
        scene_.emission[b] = buffers_.back()->get();
      }
    }
    std::vector<StarView> stars(in.stars.size());
    for (size_t k = 0; k < stars.size(); ++k) {
      stars[k].position = in.stars[k].position;
      for (int b = 0; b < scene_.n_bands; ++b) stars[k].power[b] = in.stars[k].power[b];
      buffers_.push_back(std::make_unique<DeviceArray<float>>(*in.stars[k].depth_v));
      stars[k].depth_v = buffers_.back()->get();
    }
    stars_ = std::make_unique<DeviceArray<StarView>>(stars);
    scene_.stars = stars_->get();
    scene_.n_stars = static_cast<int>(stars.size());
  }
  const MarchScene& scene() const { return scene_; }

 private:
  DeviceArray<float> density_;
  MarchScene scene_{};
  std::vector<std::unique_ptr<DeviceTable>> tables_;
  std::vector<std::unique_ptr<DeviceArray<float>>> buffers_;
  std::unique_ptr<DeviceArray<StarView>> stars_;
};

// Marches every pixel of in.camera into `pixels` (bands x height x width, on
// the device); returns the kernel's time (CUDA events).
double launch_render(const RenderInputs& in, const MarchScene& scene, float* pixels, unsigned long long* clamps) {
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

std::vector<std::string> band_names(const RenderInputs& in) {
  std::vector<std::string> names;
  for (const RenderBand& b : in.bands) names.push_back(b.name);
  return names;
}

void download(const DeviceArray<float>& from, Image& to) {
  NEBULA_CUDA_CHECK(cudaMemcpy(to.pixels.data(), from.get(), to.pixels.size() * sizeof(float), cudaMemcpyDeviceToHost));
}

uint64_t download_count(const DeviceArray<unsigned long long>& from) {
  unsigned long long count = 0;
  NEBULA_CUDA_CHECK(cudaMemcpy(&count, from.get(), sizeof count, cudaMemcpyDeviceToHost));
  return count;
}

// S_j = max(I_j - down(I_{j-1}), 0) + up(S_{j+1}) over level j's pixels, all bands.
__global__ void pyramid_sum_kernel(const float* level, const float* finer, int w_finer, int h_finer,
                                   const float* coarser, int w_coarser, int h_coarser, int w, int h, int n_bands,
                                   float* sum) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= w || y >= h) return;
  for (int b = 0; b < n_bands; ++b) {
    const size_t plane = size_t(w) * h, plane_finer = size_t(w_finer) * h_finer,
                 plane_coarser = size_t(w_coarser) * h_coarser;
    sum[b * plane + size_t(y) * w + x] =
        pyramid_sum(level + b * plane, finer + b * plane_finer, w_finer, h_finer,
                    coarser ? coarser + b * plane_coarser : nullptr, w_coarser, h_coarser, w, x, y);
  }
}

// image += up(S_1) at full resolution.
__global__ void pyramid_add_kernel(float* image, int w, int h, const float* sum, int w_sum, int h_sum, int n_bands) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= w || y >= h) return;
  for (int b = 0; b < n_bands; ++b)
    image[b * size_t(w) * h + size_t(y) * w + x] += bilinear_up(sum + b * size_t(w_sum) * h_sum, w_sum, h_sum, x, y);
}

dim3 blocks_for(int w, int h, dim3 block) { return dim3((w + block.x - 1) / block.x, (h + block.y - 1) / block.y); }

}  // namespace

Image render_cuda(const RenderInputs& in, RenderStats* stats) {
  const DeviceScene device(in);
  Image image(in.camera.width, in.camera.height, band_names(in));
  DeviceArray<float> pixels(image.pixels.size());
  DeviceArray<unsigned long long> clamps(1);
  const double march_seconds = launch_render(in, device.scene(), pixels.get(), clamps.get());
  download(pixels, image);
  if (stats) {
    stats->seconds = march_seconds;
    stats->table_clamps = download_count(clamps);
  }
  return image;
}

PyramidResult render_pyramid_cuda(const RenderInputs& in, const PreparedPyramid& prepared, bool keep_levels) {
  const int n = static_cast<int>(prepared.levels.size());
  const int n_bands = static_cast<int>(in.bands.size());
  PyramidResult out;
  std::vector<std::unique_ptr<DeviceArray<float>>> images;  // I_0 .. I_n on the device
  std::vector<Camera> cameras{in.camera};
  for (int j = 0; j <= n; ++j) {
    if (j > 0) cameras.push_back(coarser_camera(cameras.back()));
    const RenderInputs level_in = j == 0 ? in : level_inputs(in, prepared.levels[j - 1], cameras[j]);
    const DeviceScene device(level_in);
    images.push_back(std::make_unique<DeviceArray<float>>(size_t(n_bands) * cameras[j].width * cameras[j].height));
    DeviceArray<unsigned long long> clamps(1);
    PyramidLevelReport r = j == 0 ? PyramidLevelReport{} : prepared.levels[j - 1].report;
    if (j == 0) r.shape = in.density->shape;
    r.width = cameras[j].width;
    r.height = cameras[j].height;
    r.render_seconds = launch_render(level_in, device.scene(), images.back()->get(), clamps.get());
    r.table_clamps = download_count(clamps);
    out.report.push_back(r);
    if (keep_levels) {
      out.levels.emplace_back(cameras[j].width, cameras[j].height, band_names(in));
      download(*images.back(), out.levels.back());
    }
  }
  // The combination, coarsest first, entirely on the device.
  const dim3 block(16, 16);
  std::vector<std::unique_ptr<DeviceArray<float>>> sums(n + 1);  // S_1 .. S_n
  for (int j = 1; j <= n; ++j)
    sums[j] = std::make_unique<DeviceArray<float>>(size_t(n_bands) * cameras[j].width * cameras[j].height);
  CudaEventTimer timer;
  for (int j = n; j >= 1; --j) {
    const int w = cameras[j].width, h = cameras[j].height;
    pyramid_sum_kernel<<<blocks_for(w, h, block), block>>>(
        images[j]->get(), images[j - 1]->get(), cameras[j - 1].width, cameras[j - 1].height,
        j < n ? sums[j + 1]->get() : nullptr, j < n ? cameras[j + 1].width : 0, j < n ? cameras[j + 1].height : 0, w,
        h, n_bands, sums[j]->get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  const Camera& c0 = cameras[0];
  pyramid_add_kernel<<<blocks_for(c0.width, c0.height, block), block>>>(
      images[0]->get(), c0.width, c0.height, sums[1]->get(), cameras[1].width, cameras[1].height, n_bands);
  NEBULA_CUDA_CHECK(cudaGetLastError());
  out.combine_seconds = timer.seconds();
  out.image = Image(c0.width, c0.height, band_names(in));
  download(*images[0], out.image);
  return out;
}

}  // namespace nebula
