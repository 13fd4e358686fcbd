// CUDA launch of the per-star optical-depth bake; physics in the shared
// NEBULA_HD star_to_voxel_depth.
#include <cuda_runtime.h>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
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
  const DeviceArray<float> tau(grid.tau_v);
  DeviceArray<float> depth(g.count() * stars.size());
  const DensityView view{g, tau.get()};
  const dim3 block(32, 8), blocks((g.nx + 31) / 32, (g.ny + 7) / 8, g.nz);
  BakeResult out;
  CudaEventTimer timer;
  for (size_t s = 0; s < stars.size(); ++s) {
    bake_kernel<<<blocks, block>>>(view, stars[s], depth.get() + s * g.count());
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  out.seconds = timer.seconds();
  out.tau_v.assign(stars.size(), std::vector<float>(g.count()));
  for (size_t s = 0; s < stars.size(); ++s)
    NEBULA_CUDA_CHECK(cudaMemcpy(out.tau_v[s].data(), depth.get() + s * g.count(), g.count() * sizeof(float),
                                 cudaMemcpyDeviceToHost));
  return out;
}

}  // namespace nebula
