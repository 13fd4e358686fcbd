// CUDA launch of the diffuse bake's photon pass: the pass scene assembled with
// a device placement, one thread per photon running the shared
// trace_diffuse_photon, 64-bit integer atomics for the fixed-point sums (their
// order does not change them).
#include <cuda_runtime.h>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "diffuse/diffuse_bake.h"

namespace nebula {
namespace {

__global__ void diffuse_photon_kernel(DiffusePhotonScene scene, uint64_t photons, unsigned long long* sums,
                                      unsigned long long* odd, unsigned long long* counters) {
  PhotonCounters c;
  const uint64_t stride = uint64_t(gridDim.x) * blockDim.x;
  for (uint64_t p = uint64_t(blockIdx.x) * blockDim.x + threadIdx.x; p < photons; p += stride)
    trace_diffuse_photon(
        scene, static_cast<uint32_t>(p), [&](size_t i, unsigned long long v) { atomicAdd(&sums[i], v); },
        [&](size_t i, unsigned long long v) { atomicAdd(&odd[i], v); }, c);
  atomicAdd(&counters[0], static_cast<unsigned long long>(c.collisions));
  atomicAdd(&counters[1], static_cast<unsigned long long>(c.tentative));
  atomicAdd(&counters[2], static_cast<unsigned long long>(c.crossings));
  if (c.capped) atomicAdd(&counters[3], static_cast<unsigned long long>(c.capped));
}

}  // namespace

DiffusePassResult diffuse_pass_cuda(const DiffusePassInputs& in, uint64_t photons) {
  DevicePlacement device;
  const DiffusePhotonScene scene = assemble_photon_scene(in, device);
  DiffusePassResult out;
  out.sums.assign(in.cells.count() * size_t(scene.n_coeffs), 0ull);
  out.odd.assign(in.cells.count(), 0ull);
  DeviceArray<unsigned long long> sums(out.sums.size()), odd(out.odd.size()), counters(4);
  int sms = 0;
  NEBULA_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, 0));
  const int block = 128;
  const uint64_t wanted = (photons + block - 1) / block;
  const int blocks = static_cast<int>(wanted < uint64_t(sms) * 16 ? wanted : uint64_t(sms) * 16);
  CudaEventTimer timer;
  diffuse_photon_kernel<<<blocks, block>>>(scene, photons, sums.get(), odd.get(), counters.get());
  NEBULA_CUDA_CHECK(cudaGetLastError());
  out.seconds = timer.seconds();
  sums.download(out.sums.data());
  odd.download(out.odd.data());
  unsigned long long c[4] = {};
  counters.download(c);
  out.counters.collisions = c[0];
  out.counters.tentative = c[1];
  out.counters.crossings = c[2];
  out.counters.capped = c[3];
  out.device_bytes = device.bytes() + sums.bytes() + odd.bytes();
  return out;
}

}  // namespace nebula
