#include "diffuse/diffuse_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>

#include "core/error.h"
#include "core/placement.h"
#include "core/progress.h"

namespace nebula {
namespace {

void check_options(const DiffuseBakeOptions& o) {
  if (o.degree < 0 || o.degree > kMaxDiffuseDegree)
    throw ParameterError("diffuse_order", "must be 0 to " + std::to_string(kMaxDiffuseDegree) + ", got " +
                                              std::to_string(o.degree));
  if (o.cells < 1 || o.cells > 4096)
    throw ParameterError("diffuse_cells", "must be 1 to 4096, got " + std::to_string(o.cells));
  if (o.photons < 1 || o.photons > 0xFFFFFFFFull)
    throw ParameterError("diffuse_photons", "must be 1 to 2^32 - 1 per band, got " + std::to_string(o.photons));
  if (o.roulette_start < 1) throw ParameterError("roulette_start", "must be at least 1");
  if (o.max_orders < 0) throw ParameterError("max_orders", "must be 0 (all) or positive");
}

// The relative L2 noise of a band's l = 0 field from its two halves: the
// even and odd photons' sums are independent estimates.
double field_noise(const std::vector<unsigned long long>& l0, const std::vector<unsigned long long>& odd,
                   const GridShape& cells, const GridShape& grid, int shift) {
  double noise2 = 0, signal2 = 0;
  for (int z = 0; z < cells.nz; ++z)
    for (int y = 0; y < cells.ny; ++y)
      for (int x = 0; x < cells.nx; ++x) {
        const size_t cell = cells.index(x, y, z);
        const double volume = diffuse_cell_volume(grid, shift, x, y, z);
        const double all = double(static_cast<long long>(l0[cell]));
        const double half = double(static_cast<long long>(odd[cell]));
        noise2 += (all - 2 * half) * (all - 2 * half) / (volume * volume);
        signal2 += all * all / (volume * volume);
      }
  return signal2 > 0 ? std::sqrt(noise2 / signal2) : 0.0;
}

}  // namespace

DiffusePassResult diffuse_pass_cpu(const DiffusePassInputs& in, uint64_t photons, Progress* progress) {
  HostPlacement host;
  const DiffusePhotonScene scene = assemble_photon_scene(in, host);
  DiffusePassResult out;
  out.sums.assign(in.cells.count() * size_t(scene.n_coeffs), 0ull);
  out.odd.assign(in.cells.count(), 0ull);
  unsigned long long* sums = out.sums.data();
  unsigned long long* odd = out.odd.data();
  std::mutex counters_lock;
  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, photons, 1024), [&](const auto& range) {
    PhotonCounters c;
    for (uint64_t p = range.begin(); p != range.end(); ++p)
      trace_diffuse_photon(
          scene, static_cast<uint32_t>(p),
          [&](size_t i, unsigned long long v) { __atomic_fetch_add(&sums[i], v, __ATOMIC_RELAXED); },
          [&](size_t i, unsigned long long v) { __atomic_fetch_add(&odd[i], v, __ATOMIC_RELAXED); }, c);
    {
      std::lock_guard<std::mutex> lock(counters_lock);
      out.counters.collisions += c.collisions;
      out.counters.tentative += c.tentative;
      out.counters.crossings += c.crossings;
      out.counters.capped += c.capped;
    }
    if (progress) progress->add(range.size());
  });
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

DiffuseField bake_diffuse(const DensityGrid& density, const std::vector<DiffuseBand>& bands,
                          const std::vector<StarLight>& stars, const DiffuseBakeOptions& o, Backend backend,
                          DiffuseBakeStats* stats, Progress* progress) {
  check_options(o);
  if (bands.empty() || bands.size() > size_t(kMaxBands))
    throw Error("diffuse bake: 1 to " + std::to_string(kMaxBands) + " bands required");
  for (const StarLight& s : stars)
    if (s.power.size() != bands.size()) throw Error("diffuse bake: a star lacks band powers");
  for (const DiffuseBand& b : bands)
    if (b.albedo > 0 && !b.table) throw Error("diffuse bake: band " + b.name + " scatters but has no table");
  DiffuseField field;
  field.degree = o.degree;
  field.cells = diffuse_cells(density.shape, o.cells, &field.shift);
  DiffuseBakeStats st;
  st.noise.assign(bands.size(), -1.0);
  const MajorantGrid majorant = build_majorant_grid(density, o.majorant_block);
  const int n_coeffs = field.n_coeffs();
  const GridShape& cells = field.cells;
  const GridShape& grid = density.shape;
  // One pass per band that scatters light from a star.
  std::vector<DiffusePassInputs> passes;
  std::vector<double> units;
  for (size_t b = 0; b < bands.size(); ++b) {
    const DiffuseBand& band = bands[b];
    if (!(band.albedo > 0) || stars.empty()) continue;
    double total = 0;
    for (const StarLight& s : stars) total += std::max(0.0f, s.power[b]);
    if (!(total > 0)) continue;
    DiffusePassInputs in;
    in.density = &density;
    in.majorant = &majorant;
    double running = 0;
    for (const StarLight& s : stars) {
      in.stars.push_back(s.position);
      running += std::max(0.0f, s.power[b]);
      in.star_cdf.push_back(static_cast<float>(running / total));
    }
    in.star_cdf.back() = 1.0f;
    in.band = band;
    in.band_index = static_cast<uint32_t>(b);
    in.cells = cells;
    in.degree = o.degree;
    in.seed = o.seed;
    in.roulette_start = o.roulette_start;
    in.max_orders = o.max_orders;
    passes.push_back(std::move(in));
    // Sums of weight x (chord / edge) x Y, each weight in units of the total
    // power / photons: L_k = sum x (power / photons) x edge / (volume inside the grid).
    units.push_back(total / double(o.photons) * cells.voxel / kDiffuseFixedScale);
  }
  std::vector<DiffusePassResult> results;
  const bool on_device = backend == Backend::Cuda && !passes.empty();
  field.allocate(bands.size(), /*on_host=*/!on_device);
  if (on_device) {
    results = diffuse_passes_cuda(passes, units, o.photons, grid, &field);
  } else {
    std::vector<float>& packed = field.packed_for_writing();
    for (size_t p = 0; p < passes.size(); ++p) {
      DiffusePassResult pass = diffuse_pass_cpu(passes[p], o.photons, progress);
      const size_t b = passes[p].band_index;
      tbb::parallel_for(0, cells.nz, [&](int z) {
        for (int y = 0; y < cells.ny; ++y)
          for (int x = 0; x < cells.nx; ++x) {
            const size_t cell = cells.index(x, y, z);
            const double volume = diffuse_cell_volume(grid, field.shift, x, y, z);
            for (int k = 0; k < n_coeffs; ++k) {
              const size_t i = cell * size_t(n_coeffs) + size_t(k);
              packed[i * 4 + b] = diffuse_coefficient(pass.sums[i], units[p], volume);
            }
          }
      });
      results.push_back(std::move(pass));
    }
  }
  for (size_t p = 0; p < passes.size(); ++p) {
    const DiffusePassResult& pass = results[p];
    const size_t b = passes[p].band_index;
    st.seconds += pass.seconds;
    st.photons += o.photons;
    st.counters.collisions += pass.counters.collisions;
    st.counters.tentative += pass.counters.tentative;
    st.counters.crossings += pass.counters.crossings;
    st.counters.capped += pass.counters.capped;
    st.work_bytes = std::max(st.work_bytes, (pass.sums.size() + pass.odd.size()) * sizeof(unsigned long long) +
                                                pass.device_bytes);
    std::vector<unsigned long long> l0;
    const std::vector<unsigned long long>* l0_sums = &pass.sums;
    if (pass.sums.size() != cells.count()) {  // all harmonics (CPU): take k = 0
      l0.resize(cells.count());
      for (size_t c = 0; c < l0.size(); ++c) l0[c] = pass.sums[c * size_t(n_coeffs)];
      l0_sums = &l0;
    }
    st.noise[b] = field_noise(*l0_sums, pass.odd, cells, grid, field.shift);
    field.response[b] = delta_m_response(*bands[b].table, o.degree);
    field.response_tau_max[b] = static_cast<float>(bands[b].table->tau_max());
  }
  st.field_bytes = field.bytes();
  if (stats) *stats = st;
  return field;
}

}  // namespace nebula
