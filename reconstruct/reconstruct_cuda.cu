// Powell's reconstruction on the GPU: one block per (column, band), as in the
// thesis, every block running the shared powell_column (powell_column.h)
// with its threads as the team and its scratch in shared memory.
#include <cuda_runtime.h>

#include <vector>

#include "core/cuda_check.h"
#include "core/device_array.h"
#include "core/error.h"
#include "reconstruct/projection.h"
#include "reconstruct/reconstruct.h"

namespace nebula {
namespace {

constexpr int kThreads = 128;

// A CUDA block as powell_column's team: sums reduce within each warp by
// shuffles, then across the warps through shared memory; every thread gets
// the same totals.
struct BlockTeam {
  float* partial;  // 4 x (kThreads / 32) floats of shared memory
  __device__ int rank() const { return threadIdx.x; }
  __device__ int size() const { return blockDim.x; }
  __device__ void sync() { __syncthreads(); }
  template <int K>
  __device__ void sum(float (&v)[K]) {
    static_assert(K <= 4, "at most 4 sums at once");
    constexpr int kWarps = kThreads / 32;
    const int lane = threadIdx.x & 31, warp = threadIdx.x >> 5;
    for (int k = 0; k < K; ++k)
      for (int offset = 16; offset > 0; offset /= 2) v[k] += __shfl_down_sync(0xffffffffu, v[k], offset);
    if (lane == 0)
      for (int k = 0; k < K; ++k) partial[k * kWarps + warp] = v[k];
    __syncthreads();
    for (int k = 0; k < K; ++k) {
      float total = 0.0f;
      for (int w = 0; w < kWarps; ++w) total += partial[k * kWarps + w];  // the same order in every thread
      v[k] = total;
    }
    __syncthreads();  // every thread has read the totals before the next sum writes
  }
};

__global__ void __launch_bounds__(kThreads) powell_kernel(ColumnSystem system, const float* profiles, PowellSettings s,
                                                         float* out, unsigned long long* sweeps) {
  extern __shared__ float shared[];
  const int n = system.n;
  BlockTeam team{shared};
  float* w = shared + 4 * (kThreads / 32);
  const PowellWork work{w, w + n, w + 2 * n, w + 3 * n, w + 4 * n, w + 5 * n};
  const size_t column = blockIdx.x;
  const int run = powell_column(team, system, profiles + column * n, s, work);
  for (int i = threadIdx.x; i < n; i += blockDim.x) out[column * n + i] = work.e[i];
  if (threadIdx.x == 0) atomicAdd(sweeps, static_cast<unsigned long long>(run));
}

}  // namespace

std::vector<float> powell_columns_cuda(const ColumnProjection& projection, const std::vector<float>& profiles,
                                       int count, const PowellSettings& settings, long long* sweeps) {
  const int n = projection.n;
  const size_t shared = (4 * size_t(kThreads / 32) + 6 * size_t(n)) * sizeof(float);
  int device = 0, limit = 0;
  NEBULA_CUDA_CHECK(cudaGetDevice(&device));
  NEBULA_CUDA_CHECK(cudaDeviceGetAttribute(&limit, cudaDevAttrMaxSharedMemoryPerBlockOptin, device));
  if (shared > size_t(limit))
    throw ParameterError("radius", std::to_string(n) + " texels need " + std::to_string(shared) +
                                       " bytes of shared memory per block; this GPU has " + std::to_string(limit));
  NEBULA_CUDA_CHECK(cudaFuncSetAttribute(powell_kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(shared)));
  DeviceArray<float> a(projection.a);
  DeviceArray<int> row_end(projection.row_end), col_begin(projection.col_begin);
  DeviceArray<float> p(profiles), out(size_t(count) * n);
  DeviceArray<unsigned long long> total(1);
  const unsigned long long zero = 0;
  total.upload(&zero);
  const ColumnSystem system{n, a.get(), row_end.get(), col_begin.get()};
  if (count > 0) powell_kernel<<<count, kThreads, shared>>>(system, p.get(), settings, out.get(), total.get());
  NEBULA_CUDA_CHECK(cudaGetLastError());
  NEBULA_CUDA_CHECK(cudaDeviceSynchronize());
  std::vector<float> result(size_t(count) * n);
  out.download(result.data());
  unsigned long long run = 0;
  total.download(&run);
  if (sweeps) *sweeps = static_cast<long long>(run);
  return result;
}

}  // namespace nebula
