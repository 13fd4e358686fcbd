// CUDA launch of the axial marcher: uploads the map, its skip structures, the
// baked depths and the tables, then one thread per pixel runs the shared
// march_axial_ray.
#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/device_array.h"
#include "core/cuda_timer.h"
#include "raycast/axial_renderer.h"
#include "tables/device_table.h"

namespace nebula {
namespace {

// Blocks of 256 threads per SM the compiler must fit in registers.
#ifndef NEBULA_AXIAL_MIN_BLOCKS
#define NEBULA_AXIAL_MIN_BLOCKS 3  // with the band loops unrolled, at most 80 registers: 15-35% faster (H100, docs/performance.md)
#endif

// One instantiation per skip mode and star use: each kernel holds only its
// mode's checks and gets its own register allocation; the physics is the
// same template.
template <AxialSkip kMode, bool kStars>
__global__ void __launch_bounds__(256, NEBULA_AXIAL_MIN_BLOCKS)
    axial_kernel(AxialMarchScene scene, Camera camera, float exposure, float* pixels, unsigned long long* clamps) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  const RayResult r = march_axial_ray<kMode, kStars>(scene, origin, dir);
  const size_t plane = size_t(camera.width) * camera.height;
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < scene.n_bands) pixels[b * plane + size_t(y) * camera.width + x] = exposure * r.radiance[b];
  if (r.table_clamps) atomicAdd(clamps, static_cast<unsigned long long>(r.table_clamps));
}

}  // namespace

Image render_axial_cuda(const AxialRenderInputs& in, AxialRenderStats* stats) {
  validate(in);
  const AxialMap& m = *in.map;
  AxialMarchScene scene{};
  scene.map = m.view();  // host pointers, replaced below
  std::vector<std::unique_ptr<DeviceArray<float>>> floats;
  size_t bytes = 0;
  auto upload = [&](const std::vector<float>& v) {
    floats.push_back(std::make_unique<DeviceArray<float>>(v));
    bytes += floats.back()->bytes();
    return floats.back()->get();
  };
  scene.map.tau_v = upload(m.tau_v);
  for (int b = 0; b < kAxialMaxBands; ++b) scene.map.emission[b] = nullptr;
  for (size_t b = 0; b < m.emission.size(); ++b) scene.map.emission[b] = upload(m.emission[b]);
  DeviceArray<int> height(m.height), floor(m.floor), tree(m.tree), floor_tree(m.floor_tree);
  bytes += height.bytes() + floor.bytes() + tree.bytes() + floor_tree.bytes();
  DeviceArray<uint8_t> distance(m.distance);
  bytes += distance.bytes();
  scene.map.distance = distance.get();
  scene.map.height = height.get();
  scene.map.floor = floor.get();
  scene.map.tree = tree.get();
  scene.map.floor_tree = floor_tree.get();
  scene.n_bands = static_cast<int>(in.bands.size());
  scene.min_transmittance = in.min_transmittance;
  scene.step = effective_step(in);
  scene.skip = effective_skip(in);
  std::vector<std::unique_ptr<DeviceTable>> tables;
  for (int b = 0; b < scene.n_bands; ++b) {
    const AxialRenderBand& band = in.bands[size_t(b)];
    scene.extinction_ratio[b] = band.extinction_ratio;
    scene.albedo[b] = band.table ? band.albedo : 0.0f;
    scene.table[b] = TableView{};
    if (band.table) {
      tables.push_back(std::make_unique<DeviceTable>(*band.table));
      scene.table[b] = tables.back()->view();
      bytes += band.table->P.size() * sizeof(float);
    }
  }
  std::vector<AxialStarView> stars(in.stars.size());
  for (size_t k = 0; k < stars.size(); ++k) {
    stars[k].position = in.stars[k].position;
    for (int b = 0; b < scene.n_bands; ++b) stars[k].power[b] = in.stars[k].power[size_t(b)];
    stars[k].depth_v = upload(*in.stars[k].depth_v);
  }
  DeviceArray<AxialStarView> device_stars(stars);
  scene.stars = device_stars.get();
  scene.n_stars = static_cast<int>(stars.size());

  std::vector<std::string> names;
  for (const AxialRenderBand& b : in.bands) names.push_back(b.name);
  Image image(in.camera.width, in.camera.height, names);
  DeviceArray<float> pixels(image.pixels.size());
  DeviceArray<unsigned long long> clamps(1);
#ifndef NEBULA_AXIAL_BLOCK_X
#define NEBULA_AXIAL_BLOCK_X 16
#endif
  constexpr int bx = NEBULA_AXIAL_BLOCK_X, by = 256 / bx;
  const dim3 block(bx, by), grid((in.camera.width + bx - 1) / bx, (in.camera.height + by - 1) / by);
  CudaEventTimer timer;
  dispatch_axial(scene.skip, scene.n_stars > 0, [&](auto mode, auto has_stars) {
    axial_kernel<decltype(mode)::value, decltype(has_stars)::value>
        <<<grid, block>>>(scene, in.camera, in.exposure, pixels.get(), clamps.get());
  });
  NEBULA_CUDA_CHECK(cudaGetLastError());
  const double seconds = timer.seconds();
  NEBULA_CUDA_CHECK(cudaMemcpy(image.pixels.data(), pixels.get(), image.pixels.size() * sizeof(float),
                               cudaMemcpyDeviceToHost));
  unsigned long long clamp_count = 0;
  NEBULA_CUDA_CHECK(cudaMemcpy(&clamp_count, clamps.get(), sizeof clamp_count, cudaMemcpyDeviceToHost));
  if (stats) {
    stats->seconds = seconds;
    stats->table_clamps = clamp_count;
    stats->device_bytes = bytes;
    stats->skip_used = scene.skip;
  }
  return image;
}

}  // namespace nebula
