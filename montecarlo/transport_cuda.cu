// CUDA backend of the tabulator and the slab. The physics is the NEBULA_HD
// code shared with the CPU; only the launch and the tally plumbing live here.
#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

#include "core/cuda_check.h"
#include "core/device_array.h"
#include "core/cuda_timer.h"
#include "core/progress.h"
#include "montecarlo/slab.h"
#include "montecarlo/tabulate.h"

namespace nebula {
namespace {

using ull = unsigned long long;
constexpr int kThreads = 256;
constexpr uint32_t kSpherePhotonsPerBlock = 16384;  // 64 photons per thread
// Resident blocks per SM the compiler must allow for (caps registers per thread).
#ifndef NEBULA_SPHERE_MIN_BLOCKS
#define NEBULA_SPHERE_MIN_BLOCKS 4  // 64 registers: 5% faster than 71 on an H200
#endif

__device__ ull warp_sum(ull v) {
  for (int offset = 16; offset > 0; offset >>= 1) v += __shfl_down_sync(0xffffffffu, v, offset);
  return v;
}

// One global atomic per warp instead of one per thread.
__device__ void warp_add_to(ull* target, ull v) {
  v = warp_sum(v);
  if ((threadIdx.x & 31) == 0 && v) atomicAdd(target, v);
}

struct SharedSphereSink {
  ull* hist;  // [2][n_mu] in shared memory
  int n_mu;
  ull capped = 0, capped_weight = 0;
  __device__ void add_bin(int k, uint64_t x, uint64_t x2) {
    atomicAdd(&hist[k], static_cast<ull>(x));
    atomicAdd(&hist[n_mu + k], static_cast<ull>(x2));
  }
  __device__ void add_capped(uint64_t x) {
    ++capped;
    capped_weight += x;
  }
};

// Grid: x = chunk of photons, y = row (heaviest rows first). A thread takes
// the block's next photon as soon as its last one ends, so the lanes of a warp
// stay busy although photons live for very different numbers of steps, and
// every step runs the same code (transport_step) for every lane.
__global__ void __launch_bounds__(kThreads, NEBULA_SPHERE_MIN_BLOCKS)
    sphere_kernel(const SphereRow* rows, int row_end, int n_mu, ull* sum_w, ull* sum_w2, ull* scalars) {
  extern __shared__ ull hist[];
  __shared__ uint32_t next_photon;
  const int i = row_end - 1 - static_cast<int>(blockIdx.y);
  const SphereRow row = rows[i];
  // Rows differ in photons (thin rows more): blocks past a row's count leave.
  const uint32_t begin = blockIdx.x * kSpherePhotonsPerBlock;
  if (begin >= row.photons) return;
  const uint32_t end = min(row.photons, begin + kSpherePhotonsPerBlock);
  for (int k = threadIdx.x; k < 2 * n_mu; k += blockDim.x) hist[k] = 0;
  if (threadIdx.x == 0) next_photon = begin;
  __syncthreads();
  SharedSphereSink sink{hist, n_mu};
  ull unscattered = 0, events = 0;
  PhotonState st;
  uint32_t photon = 0;
  bool active = false;
  while (true) {
    if (!active) {
      photon = atomicAdd(&next_photon, 1u);
      if (photon >= end) break;
      st.draw = 0;
      active = true;
    }
    float left_unscattered;
    const Fate f = sphere_step(row, photon, st, left_unscattered);
    if (left_unscattered > 0.0f) unscattered += to_fixed(left_unscattered);
    if (f == Fate::Flying) continue;
    events += st.orders;
    tally_sphere_photon(row, st, f, sink);
    active = false;
  }
  warp_add_to(&scalars[4 * i + 0], unscattered);
  warp_add_to(&scalars[4 * i + 1], events);
  warp_add_to(&scalars[4 * i + 2], sink.capped);
  warp_add_to(&scalars[4 * i + 3], sink.capped_weight);
  __syncthreads();
  for (int k = threadIdx.x; k < n_mu; k += blockDim.x) {
    if (hist[k]) atomicAdd(&sum_w[size_t(i) * n_mu + k], hist[k]);
    if (hist[n_mu + k]) atomicAdd(&sum_w2[size_t(i) * n_mu + k], hist[n_mu + k]);
  }
}

__global__ void __launch_bounds__(kThreads) slab_kernel(SlabRun run, uint32_t begin, uint32_t end,
                                                        ull* out) {
  SlabTallies t;
  const uint32_t stride = gridDim.x * blockDim.x;
  for (uint32_t photon = begin + blockIdx.x * blockDim.x + threadIdx.x; photon < end;
       photon += stride)
    run_slab_photon(run, photon, t);
  const ull v[8] = {t.sum_r, t.sum_r2, t.sum_t, t.sum_t2,
                    t.unscattered, t.events, t.capped, t.capped_weight};
#pragma unroll
  for (int k = 0; k < 8; ++k) warp_add_to(&out[k], v[k]);
}

}  // namespace

SphereTallies tabulate_sphere_cuda(const TabulateParams& p, Progress* progress) {
  const int n_tau = p.tau_bins, n_mu = p.mu_bins;
  std::vector<SphereRow> host_rows(n_tau);
  for (int i = 0; i < n_tau; ++i) host_rows[i] = make_sphere_row(p, i);
  const DeviceArray<SphereRow> rows(host_rows);
  DeviceArray<ull> sum_w(size_t(n_tau) * n_mu), sum_w2(size_t(n_tau) * n_mu);
  DeviceArray<ull> scalars(size_t(4) * n_tau);

  const size_t shared = 2 * n_mu * sizeof(ull);
  NEBULA_CUDA_CHECK(cudaFuncSetAttribute(sphere_kernel, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                         static_cast<int>(shared)));
  uint32_t most = 0;
  for (const SphereRow& r : host_rows) most = std::max(most, r.photons);
  const uint32_t chunks = (most + kSpherePhotonsPerBlock - 1) / kSpherePhotonsPerBlock;
  // With a progress bar, launch ~20 slices of rows and report after each;
  // without one, a single launch (no tail between slices).
  const int rows_per_launch = progress ? std::max(1, (n_tau + 19) / 20) : n_tau;
  CudaEventTimer timer;
  for (int row_end = n_tau; row_end > 0; row_end -= rows_per_launch) {
    const int count = std::min(rows_per_launch, row_end);
    sphere_kernel<<<dim3(chunks, count), kThreads, shared>>>(rows.get(), row_end, n_mu, sum_w.get(), sum_w2.get(),
                                                              scalars.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
    if (progress) {
      NEBULA_CUDA_CHECK(cudaDeviceSynchronize());
      uint64_t done = 0;
      for (int i = row_end - count; i < row_end; ++i) done += host_rows[i].photons;
      progress->add(done);
    }
  }
  const double transport_seconds = timer.seconds();

  SphereTallies t;
  t.resize(n_tau, n_mu);
  t.compute_seconds = transport_seconds;
  std::vector<ull> w(sum_w.size()), w2(sum_w2.size()), s(scalars.size());
  sum_w.download(w.data());
  sum_w2.download(w2.data());
  scalars.download(s.data());
  std::copy(w.begin(), w.end(), t.sum_w.begin());
  std::copy(w2.begin(), w2.end(), t.sum_w2.begin());
  for (int i = 0; i < n_tau; ++i) {
    t.unscattered[i] = s[4 * i + 0];
    t.events[i] = s[4 * i + 1];
    t.capped[i] = s[4 * i + 2];
    t.capped_weight[i] = s[4 * i + 3];
  }
  return t;
}

SlabTallies simulate_slab_cuda(const SlabParams& p, Progress* progress) {
  const SlabRun run = make_slab_run(p);
  DeviceArray<ull> out(8);
  const auto photons = static_cast<uint32_t>(p.photons);
  int sms = 0;
  NEBULA_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, 0));
  const uint32_t slice = std::max<uint32_t>(1u << 20, (photons + 19) / 20);
  for (uint32_t begin = 0; begin < photons; begin += slice) {
    const uint32_t end = std::min(photons, begin + slice);
    const uint32_t blocks = std::min<uint32_t>(sms * 8, (end - begin + kThreads - 1) / kThreads);
    slab_kernel<<<blocks, kThreads>>>(run, begin, end, out.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
    NEBULA_CUDA_CHECK(cudaDeviceSynchronize());
    if (progress) progress->add(end - begin);
  }
  std::vector<ull> v(out.size());
  out.download(v.data());
  SlabTallies t;
  t.sum_r = v[0];
  t.sum_r2 = v[1];
  t.sum_t = v[2];
  t.sum_t2 = v[3];
  t.unscattered = v[4];
  t.events = v[5];
  t.capped = v[6];
  t.capped_weight = v[7];
  return t;
}

}  // namespace nebula
