// CUDA launch of the per-star optical-depth bake; physics in the shared
// NEBULA_HD star_to_voxel_depth.
#include <cuda_runtime.h>

#include <memory>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "illumination/optical_depth_bake.h"

namespace nebula {
namespace {

__global__ void bake_kernel(DensityView grid, Vec3 star, float* depth) {
  const GridShape& g = grid.shape;
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  const int z = blockIdx.z;
  if (x >= g.nx || y >= g.ny) return;
  depth[g.index(x, y, z)] = star_to_voxel_depth(grid, star, x, y, z);
}

}  // namespace

BakeResult bake_star_depths_cuda(const DensityGrid& grid, const std::vector<Vec3>& stars) {
  const GridShape& g = grid.shape;
  // The grid's device copy, uploaded once for this bake, the renders and the diffuse bake.
  DevicePlacement device;
  const DensityView view{g, device.place(grid.tau_v, grid.device_tau_v)};
  std::vector<std::shared_ptr<DeviceArray<float>>> depth;
  for (size_t s = 0; s < stars.size(); ++s) depth.push_back(std::make_shared<DeviceArray<float>>(g.count()));
  const dim3 block(32, 8), blocks((g.nx + 31) / 32, (g.ny + 7) / 8, g.nz);
  BakeResult out;
  CudaEventTimer timer;
  for (size_t s = 0; s < stars.size(); ++s) {
    bake_kernel<<<blocks, block>>>(view, stars[s], depth[s]->get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  out.seconds = timer.seconds();
  // The host copies, and the device ones kept for the marchers (BakedStar::depth_mirror).
  out.tau_v.assign(stars.size(), std::vector<float>(g.count()));
  out.device_tau_v.resize(stars.size());
  for (size_t s = 0; s < stars.size(); ++s) {
    depth[s]->download(out.tau_v[s].data());
    float* device = depth[s]->get();
    out.device_tau_v[s].set({std::move(depth[s]), device}, g.count() * sizeof(float));
  }
  return out;
}

}  // namespace nebula
