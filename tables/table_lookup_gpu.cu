#include "core/cuda_check.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "tables/table_lookup.h"
#include "tables/table_lookup_gpu.h"

namespace nebula {

namespace {

__global__ void lookup_kernel(TableView table, const float* tau, const float* mu, float* out,
                              size_t count, unsigned long long* clamped) {
  const size_t stride = static_cast<size_t>(gridDim.x) * blockDim.x;
  for (size_t j = static_cast<size_t>(blockIdx.x) * blockDim.x + threadIdx.x; j < count;
       j += stride) {
    int outside = 0;
    out[j] = table.lookup(tau[j], mu[j], &outside);
    if (outside != 0) atomicAdd(clamped, static_cast<unsigned long long>(outside));
  }
}

}  // namespace

std::vector<float> lookup_batch_gpu(const ScatteringTable& table, const std::vector<float>& tau,
                                    const std::vector<float>& mu, uint64_t* clamped_count) {
  if (tau.size() != mu.size())
    throw Error("lookup_batch_gpu: expected as many mu as tau values, found " +
                std::to_string(mu.size()) + " and " + std::to_string(tau.size()));
  const size_t count = tau.size();
  std::vector<float> result(count);
  DevicePlacement device;
  const TableView view = place_table(table, device);
  DeviceArray<float> d_tau(tau), d_mu(mu), d_out(count);
  DeviceArray<unsigned long long> d_clamped(1);
  if (count > 0) {
    const int block = 256;
    const size_t blocks_needed = (count + block - 1) / block;
    const int grid = static_cast<int>(blocks_needed < 65535 ? blocks_needed : 65535);
    lookup_kernel<<<grid, block>>>(view, d_tau.get(), d_mu.get(), d_out.get(), count, d_clamped.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  d_out.download(result.data());  // synchronises with the kernel
  unsigned long long clamped = 0;
  d_clamped.download(&clamped);
  if (clamped_count != nullptr) *clamped_count = clamped;
  return result;
}

}  // namespace nebula
