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

// One thread per harmonic of a cell: band `band`'s slot of the packed field,
// and the cell's l = 0 sum for the noise.
__global__ void coefficients_kernel(const unsigned long long* sums, GridShape cells, int n_coeffs, GridShape grid,
                                    int shift, double unit, int band, float* packed, unsigned long long* l0) {
  const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= cells.count() * size_t(n_coeffs)) return;
  const size_t cell = i / size_t(n_coeffs);
  const int x = int(cell % size_t(cells.nx)), y = int(cell / size_t(cells.nx) % size_t(cells.ny)),
            z = int(cell / (size_t(cells.nx) * cells.ny));
  packed[i * 4 + size_t(band)] = diffuse_coefficient(sums[i], unit, diffuse_cell_volume(grid, shift, x, y, z));
  if (i % size_t(n_coeffs) == 0) l0[cell] = sums[i];
}

}  // namespace

std::vector<DiffusePassResult> diffuse_passes_cuda(const std::vector<DiffusePassInputs>& passes,
                                                   const std::vector<double>& units, uint64_t photons,
                                                   const GridShape& grid, DiffuseField* field) {
  std::vector<DiffusePassResult> out;
  if (passes.empty()) return out;
  const GridShape cells = field->cells;
  const int n_coeffs = field->n_coeffs();
  const size_t harmonics = cells.count() * size_t(n_coeffs);
  // One placement for every pass: the grid comes from its device mirror
  // (uploaded once), the majorant and the stars (small) per pass.
  DevicePlacement device;
  size_t scene_bytes = 0;
  DeviceArray<unsigned long long> sums(harmonics), odd(cells.count()), l0(cells.count()), counters(4);
  auto packed = std::make_shared<DeviceArray<float>>(harmonics * 4);  // zeros: bands without a field
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
    diffuse_photon_kernel<<<blocks, block>>>(scene, photons, sums.get(), odd.get(), counters.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
    r.seconds = timer.seconds();
    const unsigned convert_blocks = static_cast<unsigned>((harmonics + 255) / 256);
    coefficients_kernel<<<convert_blocks, 256>>>(sums.get(), cells, n_coeffs, grid, field->shift, units[p],
                                                 int(in.band_index), packed->get(), l0.get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
    r.sums.resize(cells.count());
    r.odd.resize(cells.count());
    l0.download(r.sums.data());
    odd.download(r.odd.data());
    unsigned long long c[4] = {};
    counters.download(c);
    r.counters.collisions = c[0];
    r.counters.tentative = c[1];
    r.counters.crossings = c[2];
    r.counters.capped = c[3];
    r.device_bytes = scene_bytes + sums.bytes() + odd.bytes() + l0.bytes() + packed->bytes();
    out.push_back(std::move(r));
  }
  const size_t bytes = packed->bytes();
  const void* on_device = packed->get();
  field->device_packed.set({std::move(packed), on_device}, bytes);
  return out;
}

}  // namespace nebula
