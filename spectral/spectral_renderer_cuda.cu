// CUDA launch of the spectral marcher: the model's tables, the grid and the
// baked depths uploaded, then one thread per pixel runs the shared
// march_spectral (spectral/spectral_march.h) and writes its accumulators.
#include <cuda_runtime.h>

#include <memory>
#include <string>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "spectral/spectral_renderer.h"

namespace nebula::spectral {
namespace {

template <SpectralMethod kMethod>
__global__ void spectral_kernel(SpectralSceneView scene, Camera camera, float* pixels) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  float acc[kMaxAccumulators];
  march_spectral<kMethod>(scene, origin, dir, acc);
  const size_t plane = size_t(camera.width) * camera.height;
  for (int k = 0; k < scene.n_acc; ++k) pixels[k * plane + size_t(y) * camera.width + x] = acc[k];
}

// VoxelLight's per-view pre-pass: one thread per voxel (spectral_march.h).
__global__ void voxel_light_kernel(SpectralSceneView scene, Camera camera, float* light, unsigned* near) {
  const GridShape& g = scene.density.shape;
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= g.count()) return;
  const int x = int(i % g.nx), y = int((i / g.nx) % g.ny), z = int(i / (size_t(g.nx) * g.ny));
  voxel_light<1>(scene, camera, x, y, z, light, near);
}

template <class T>
const T* upload(std::vector<std::unique_ptr<DeviceArray<T>>>& keep, const std::vector<T>& host) {
  if (host.empty()) return nullptr;
  keep.push_back(std::make_unique<DeviceArray<T>>(host));
  return keep.back()->get();
}

}  // namespace

Image render_spectral_cuda(const SpectralRenderInputs& in, double* seconds) {
  const SpectralModel& m = *in.model;
  std::vector<std::unique_ptr<DeviceArray<float>>> floats;
  std::vector<std::unique_ptr<DeviceArray<double>>> doubles;
  std::vector<std::unique_ptr<DeviceArray<SpectralStarView>>> star_arrays;
  SpectralSceneView view = view_of(m);
  view.density = {in.density->shape, upload(floats, in.density->tau_v)};
  std::vector<SpectralStarView> stars;
  for (size_t k = 0; k < in.lights.size(); ++k)
    stars.push_back({in.lights[k].position, float(in.lights[k].luminosity_lsun), upload(floats, *in.lights[k].depth_v),
                     m.temperature_u.empty() ? 0.0f : m.temperature_u[k]});
  star_arrays.push_back(std::make_unique<DeviceArray<SpectralStarView>>(stars));
  view.stars = stars.empty() ? nullptr : star_arrays.back()->get();
  view.n_stars = int(stars.size());
  view.albedo = in.albedo;
  view.g = in.g;
  view.footprint = in.camera.footprint();
  view.kappa = upload(floats, m.kappa);
  view.q = upload(floats, m.q);
  view.coeff = upload(floats, m.coeff);
  view.breaks = upload(doubles, m.breaks);
  view.coefficients = upload(doubles, m.coefficients);
  view.star_coeff = upload(floats, m.star_coeff);
  const bool voxel = m.settings.method == SpectralMethod::VoxelLight;
  const size_t cells = in.density->shape.count();
  DeviceArray<float> light(voxel ? cells * 4 * size_t(m.n_acc) * m.basis.size() : 0);
  DeviceArray<unsigned> near(voxel ? cells : 0);
  if (voxel) {
    view.near_distance = float(m.settings.near_voxels) * in.density->shape.voxel;
    view.voxel_light = light.get();
    view.near_stars = near.get();
  }
  std::vector<std::string> names;
  for (int k = 0; k < m.n_acc; ++k) names.push_back("acc" + std::to_string(k));
  Image image(in.camera.width, in.camera.height, names);
  DeviceArray<float> pixels(image.pixels.size());
  const dim3 block(16, 16), grid((in.camera.width + 15) / 16, (in.camera.height + 15) / 16);
  CudaEventTimer timer;
  if (voxel)  // the pre-pass, timed with the march
    voxel_light_kernel<<<unsigned((cells + 255) / 256), 256>>>(view, in.camera, light.get(), near.get());
  dispatch_method(m.settings.method, [&](auto method) {
    spectral_kernel<method()><<<grid, block>>>(view, in.camera, pixels.get());
  });
  NEBULA_CUDA_CHECK(cudaGetLastError());
  const double s = timer.seconds();
  if (seconds) *seconds = s;
  pixels.download(image.pixels.data());
  return image;
}

}  // namespace nebula::spectral
