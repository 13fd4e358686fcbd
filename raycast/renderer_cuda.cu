// CUDA launch of the ray marcher: uploads the grids, tables and baked depths,
// then one thread per pixel runs the shared march_ray.
#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "raycast/renderer.h"
#include "tables/device_table.h"

namespace nebula {
namespace {

// Device copy of a host vector, freed on scope exit.
template <class T>
class DeviceArray {
 public:
  explicit DeviceArray(const std::vector<T>& host) : size_(host.size()) {
    NEBULA_CUDA_CHECK(cudaMalloc(&ptr_, std::max<size_t>(1, size_) * sizeof(T)));
    if (size_)
      NEBULA_CUDA_CHECK(cudaMemcpy(ptr_, host.data(), size_ * sizeof(T), cudaMemcpyHostToDevice));
  }
  explicit DeviceArray(size_t n) : size_(n) {
    NEBULA_CUDA_CHECK(cudaMalloc(&ptr_, std::max<size_t>(1, n) * sizeof(T)));
    NEBULA_CUDA_CHECK(cudaMemset(ptr_, 0, std::max<size_t>(1, n) * sizeof(T)));
  }
  ~DeviceArray() { cudaFree(ptr_); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
  T* get() const { return ptr_; }

 private:
  T* ptr_ = nullptr;
  size_t size_ = 0;
};

template <bool kSmooth>
__global__ void render_kernel(MarchScene scene, Camera camera, MarchMode mode, float exposure,
                              float* pixels, unsigned long long* clamps) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  const RayResult r = march_ray_in_mode<kSmooth>(scene, origin, dir, mode);
  const size_t plane = size_t(camera.width) * camera.height;
  for (int b = 0; b < scene.n_bands; ++b) pixels[b * plane + size_t(y) * camera.width + x] = exposure * r.radiance[b];
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

}  // namespace

Image render_cuda(const RenderInputs& in, RenderStats* stats) {
  validate(in);
  MarchScene scene{};
  DeviceArray<float> density(in.density->tau_v);
  scene.density = {in.density->shape, density.get()};
  scene.n_bands = static_cast<int>(in.bands.size());
  scene.min_transmittance = in.min_transmittance;
  std::vector<std::unique_ptr<DeviceTable>> tables;
  std::vector<std::unique_ptr<DeviceArray<float>>> buffers;
  for (int b = 0; b < scene.n_bands; ++b) {
    const RenderBand& band = in.bands[b];
    scene.extinction_ratio[b] = band.extinction_ratio;
    scene.albedo[b] = band.albedo;
    scene.table[b] = TableView{};
    if (band.table) {
      tables.push_back(std::make_unique<DeviceTable>(*band.table));
      scene.table[b] = tables.back()->view();
    }
    scene.emission[b] = nullptr;
    if (band.emission) {
      buffers.push_back(std::make_unique<DeviceArray<float>>(*band.emission));
      scene.emission[b] = buffers.back()->get();
    }
  }
  std::vector<StarView> stars(in.stars.size());
  for (size_t k = 0; k < stars.size(); ++k) {
    stars[k].position = in.stars[k].position;
    for (int b = 0; b < scene.n_bands; ++b) stars[k].power[b] = in.stars[k].power[b];
    buffers.push_back(std::make_unique<DeviceArray<float>>(*in.stars[k].depth_v));
    stars[k].depth_v = buffers.back()->get();
  }
  DeviceArray<StarView> device_stars(stars);
  scene.stars = device_stars.get();
  scene.n_stars = static_cast<int>(stars.size());

  std::vector<std::string> names;
  for (const RenderBand& b : in.bands) names.push_back(b.name);
  Image image(in.camera.width, in.camera.height, names);
  DeviceArray<float> pixels(image.pixels.size());
  DeviceArray<unsigned long long> clamps(1);
  const dim3 block(16, 16), grid((in.camera.width + 15) / 16, (in.camera.height + 15) / 16);
  CudaEventTimer timer;
  // One kernel per mode: the exact one carries none of the smooth mode's code.
  if (in.mode.step_voxels > 0.0f)
    render_kernel<true><<<grid, block>>>(scene, in.camera, in.mode, in.exposure, pixels.get(), clamps.get());
  else
    render_kernel<false><<<grid, block>>>(scene, in.camera, in.mode, in.exposure, pixels.get(), clamps.get());
  NEBULA_CUDA_CHECK(cudaGetLastError());
  const double march_seconds = timer.seconds();
  NEBULA_CUDA_CHECK(cudaMemcpy(image.pixels.data(), pixels.get(), image.pixels.size() * sizeof(float),
                               cudaMemcpyDeviceToHost));
  unsigned long long clamp_count = 0;
  NEBULA_CUDA_CHECK(cudaMemcpy(&clamp_count, clamps.get(), sizeof clamp_count, cudaMemcpyDeviceToHost));
  if (stats) {
    stats->seconds = march_seconds;
    stats->table_clamps = clamp_count;
  }
  return image;
}

}  // namespace nebula
