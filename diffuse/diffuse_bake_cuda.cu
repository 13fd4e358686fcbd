// CUDA launch of the diffuse bake: the grid uploaded once (its device
// mirror) for every band's photon pass, one thread per photon running the shared
// trace_diffuse_photon, 64-bit integer atomics for the fixed-point sums
// (their order does not change them), then the harmonics made from the sums
// on the device, where the marchers read them (DiffuseField::device_packed).
#include <cuda_runtime.h>

#include <memory>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "core/error.h"
#include "diffuse/diffuse_bake.h"

namespace nebula {
namespace {

template <bool kShared, bool kZonal>
__global__ void diffuse_photon_kernel(DiffusePhotonScene scene, uint64_t photons, unsigned long long* sums,
                                      unsigned long long* odd, unsigned long long* counters) {
  PhotonCounters c;
  const uint64_t stride = uint64_t(gridDim.x) * blockDim.x;
  for (uint64_t p = uint64_t(blockIdx.x) * blockDim.x + threadIdx.x; p < photons; p += stride)
    trace_diffuse_photon<kShared, kZonal>(
        scene, static_cast<uint32_t>(p), [&](size_t i, unsigned long long v) { atomicAdd(&sums[i], v); },
        [&](size_t i, unsigned long long v) { atomicAdd(&odd[i], v); }, c);
  atomicAdd(&counters[0], static_cast<unsigned long long>(c.collisions));
  atomicAdd(&counters[1], static_cast<unsigned long long>(c.tentative));
  atomicAdd(&counters[2], static_cast<unsigned long long>(c.crossings));
  if (c.capped) atomicAdd(&counters[3], static_cast<unsigned long long>(c.capped));
}

// The packed fields of a pass's slots (one per set of albedos).
struct SlotTargets {
  float* packed[kMaxAlbedoSlots] = {};
};

// One thread per harmonic of a cell and slot: band `band`'s entry of the
// slot's packed field from the pass's accumulators (DiffuseSlots), and the
// slot's l = 0 sums, all photons and the odd ones, for the noise.
__global__ void coefficients_kernel(const unsigned long long* sums, const unsigned long long* odd, DiffuseSlots layout,
                                    GridShape cells, GridShape grid, int shift, double unit, int band,
                                    SlotTargets targets, double* l0, double* odd_l0) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const int n_coeffs = layout.n_coeffs, slots = layout.slots;
  if (i >= cells.count() * size_t(slots) * size_t(n_coeffs)) return;
  const size_t cell_slot = i / size_t(n_coeffs), k = i % size_t(n_coeffs);
  const size_t cell = cell_slot / size_t(slots), slot = cell_slot % size_t(slots);
  const int x = int(cell % size_t(cells.nx)), y = int(cell / size_t(cells.nx) % size_t(cells.ny)),
            z = int(cell / (size_t(cells.nx) * cells.ny));
  const double sum = layout.sum(sums, int(slot), cell, int(k));
  targets.packed[slot][(cell * size_t(n_coeffs) + k) * 4 + size_t(band)] =
      diffuse_coefficient(sum, unit, diffuse_cell_volume(grid, shift, x, y, z));
  if (k == 0) {
    DiffuseSlots odd_layout = layout;
    odd_layout.n_coeffs = 1;
    l0[cell_slot] = sum;
    odd_l0[cell_slot] = odd_layout.sum(odd, int(slot), cell, 0);
  }
}

// Per slot (blockIdx.y) the noise's sums over the cells, reduced in each
// block and added to out[2 slot] (noise) and out[2 slot + 1] (signal).
__global__ void noise_kernel(const double* l0, const double* odd_l0, GridShape cells, GridShape grid, int shift,
                             int slots, double* out) {
  constexpr int kThreads = 256;
  __shared__ double noise[kThreads], signal[kThreads];
  const int slot = int(blockIdx.y), t = int(threadIdx.x);
  double n2 = 0, s2 = 0;
  for (size_t cell = size_t(blockIdx.x) * kThreads + size_t(t); cell < cells.count(); cell += size_t(gridDim.x) * kThreads) {
    const int x = int(cell % size_t(cells.nx)), y = int(cell / size_t(cells.nx) % size_t(cells.ny)),
              z = int(cell / (size_t(cells.nx) * cells.ny));
    diffuse_cell_noise(l0[cell * size_t(slots) + size_t(slot)], odd_l0[cell * size_t(slots) + size_t(slot)],
                       diffuse_cell_volume(grid, shift, x, y, z), n2, s2);
  }
  noise[t] = n2;
  signal[t] = s2;
  __syncthreads();
  for (int w = kThreads / 2; w > 0; w /= 2) {
    if (t < w) {
      noise[t] += noise[t + w];
      signal[t] += signal[t + w];
    }
    __syncthreads();
  }
  if (t == 0) {
    atomicAdd(&out[2 * slot], noise[0]);
    atomicAdd(&out[2 * slot + 1], signal[0]);
  }
}

}  // namespace

std::vector<DiffusePassResult> diffuse_passes_cuda(const std::vector<DiffusePassInputs>& passes,
                                                   const std::vector<double>& units, uint64_t photons,
                                                   const GridShape& grid, const std::vector<DiffuseField*>& fields) {
  std::vector<DiffusePassResult> out;
  if (passes.empty()) return out;
  const GridShape cells = fields.front()->cells;
  const int n_coeffs = fields.front()->n_coeffs();
  const int slots = static_cast<int>(fields.size());
  for (const DiffusePassInputs& in : passes)
    if (in.slots() != slots) throw Error("diffuse bake: a pass with " + std::to_string(in.slots()) + " slots for " +
                                         std::to_string(slots) + " fields");
  const size_t harmonics = cells.count() * size_t(n_coeffs);
  DiffuseSlots odd_layout = diffuse_slots(passes.front(), cells.count(), 1);
  // One placement for every pass: the grid comes from its device mirror
  // (uploaded once), the majorant and the stars (small) per pass.
  DevicePlacement device;
  size_t scene_bytes = 0;
  DeviceArray<unsigned long long> sums(diffuse_slots(passes.front(), cells.count(), n_coeffs).entries()),
      odd(odd_layout.entries()), counters(4);
  DeviceArray<double> l0(cells.count() * size_t(slots)), odd_l0(cells.count() * size_t(slots)),
      noise(2 * size_t(slots));
  std::vector<std::shared_ptr<DeviceArray<float>>> packed;
  SlotTargets targets;
  for (int s = 0; s < slots; ++s) {
    packed.push_back(std::make_shared<DeviceArray<float>>(harmonics * 4));  // zeros: bands without a field
    targets.packed[s] = packed.back()->get();
  }
  int sms = 0;
  NEBULA_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, 0));
  const int block = 128;
  const uint64_t wanted = (photons + block - 1) / block;
  const int blocks = static_cast<int>(wanted < uint64_t(sms) * 16 ? wanted : uint64_t(sms) * 16);
  for (size_t p = 0; p < passes.size(); ++p) {
    const DiffusePassInputs& in = passes[p];
    const DiffusePhotonScene scene = assemble_photon_scene(in, device);
    if (p == 0) scene_bytes = device.bytes();  // what one pass reads (later passes place the same)
    if (p > 0) {
      NEBULA_CUDA_CHECK(cudaMemset(sums.get(), 0, sums.bytes()));
      NEBULA_CUDA_CHECK(cudaMemset(odd.get(), 0, odd.bytes()));
      NEBULA_CUDA_CHECK(cudaMemset(counters.get(), 0, counters.bytes()));
    }
    DiffusePassResult r;
    CudaEventTimer timer;
    auto launch = [&](auto kernel) { kernel<<<blocks, block>>>(scene, photons, sums.get(), odd.get(), counters.get()); };
    if (scene.slots > 1 && scene.zonal > 0)
      launch(diffuse_photon_kernel<true, true>);
    else if (scene.slots > 1)
      launch(diffuse_photon_kernel<true, false>);
    else if (scene.zonal > 0)
      launch(diffuse_photon_kernel<false, true>);
    else
      launch(diffuse_photon_kernel<false, false>);
    NEBULA_CUDA_CHECK(cudaGetLastError());
    r.seconds = timer.seconds();
    const size_t entries = harmonics * size_t(slots);
    const unsigned convert_blocks = static_cast<unsigned>((entries + 255) / 256);
    coefficients_kernel<<<convert_blocks, 256>>>(sums.get(), odd.get(), diffuse_slots(in, cells.count(), n_coeffs),
                                                 cells, grid, fields.front()->shift, units[p], int(in.band_index),
                                                 targets, l0.get(), odd_l0.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
    // The noise's sums on the device: two numbers per slot come back, not the cells' sums.
    NEBULA_CUDA_CHECK(cudaMemset(noise.get(), 0, noise.bytes()));
    noise_kernel<<<dim3(64, unsigned(slots)), 256>>>(l0.get(), odd_l0.get(), cells, grid, fields.front()->shift, slots,
                                                     noise.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
    std::vector<double> sums2(2 * size_t(slots));
    noise.download(sums2.data());
    for (int s = 0; s < slots; ++s) {
      r.noise2.push_back(sums2[2 * size_t(s)]);
      r.signal2.push_back(sums2[2 * size_t(s) + 1]);
    }
    unsigned long long c[4] = {};
    counters.download(c);
    r.counters.collisions = c[0];
    r.counters.tentative = c[1];
    r.counters.crossings = c[2];
    r.counters.capped = c[3];
    r.device_bytes = scene_bytes + sums.bytes() + odd.bytes() + l0.bytes() + odd_l0.bytes() +
                     packed.size() * packed.front()->bytes();
    out.push_back(std::move(r));
  }
  for (int s = 0; s < slots; ++s) {
    const size_t bytes = packed[size_t(s)]->bytes();
    const void* on_device = packed[size_t(s)]->get();
    fields[size_t(s)]->device_packed.set({std::move(packed[size_t(s)]), on_device}, bytes);
  }
  return out;
}

}  // namespace nebula
