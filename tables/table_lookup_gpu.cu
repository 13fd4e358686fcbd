#include <utility>

#include "core/cuda_check.h"
#include "core/device_array.h"
#include "tables/device_table.h"

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

DeviceTable::DeviceTable(const ScatteringTable& table) {
  const TableView host = view_of(table);  // validates the shape
  const size_t bytes = table.P.size() * sizeof(float);
  NEBULA_CUDA_CHECK(cudaMalloc(&device_P_, bytes));
  const cudaError_t copied = cudaMemcpy(device_P_, table.P.data(), bytes, cudaMemcpyHostToDevice);
  if (copied != cudaSuccess) {
    release();
    cuda_check(copied, "cudaMemcpy(table P to device)");
  }
  view_ = host;
  view_.P = device_P_;
}

DeviceTable::~DeviceTable() { release(); }

DeviceTable::DeviceTable(DeviceTable&& other) noexcept
    : device_P_(std::exchange(other.device_P_, nullptr)), view_(std::exchange(other.view_, {})) {}

DeviceTable& DeviceTable::operator=(DeviceTable&& other) noexcept {
  if (this != &other) {
    release();
    device_P_ = std::exchange(other.device_P_, nullptr);
    view_ = std::exchange(other.view_, {});
  }
  return *this;
}

void DeviceTable::release() {
  if (device_P_ != nullptr) cudaFree(device_P_);
  device_P_ = nullptr;
  view_ = TableView{};
}

std::vector<float> lookup_batch_gpu(const ScatteringTable& table, const std::vector<float>& tau,
                                    const std::vector<float>& mu, uint64_t* clamped_count) {
  if (tau.size() != mu.size())
    throw Error("lookup_batch_gpu: expected as many mu as tau values, found " +
                std::to_string(mu.size()) + " and " + std::to_string(tau.size()));
  const size_t count = tau.size();
  std::vector<float> result(count);
  const DeviceTable device(table);
  DeviceArray<float> d_tau(count), d_mu(count), d_out(count);
  DeviceArray<unsigned long long> d_clamped(1);
  d_tau.upload(tau.data());
  d_mu.upload(mu.data());
  NEBULA_CUDA_CHECK(cudaMemset(d_clamped.get(), 0, sizeof(unsigned long long)));

  if (count > 0) {
    const int block = 256;
    const size_t blocks_needed = (count + block - 1) / block;
    const int grid = static_cast<int>(blocks_needed < 65535 ? blocks_needed : 65535);
    lookup_kernel<<<grid, block>>>(device.view(), d_tau.get(), d_mu.get(), d_out.get(), count,
                                   d_clamped.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  d_out.download(result.data());  // synchronises with the kernel
  unsigned long long clamped = 0;
  d_clamped.download(&clamped);
  if (clamped_count != nullptr) *clamped_count = clamped;
  return result;
}

}  // namespace nebula
