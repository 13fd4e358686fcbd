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

// Voxels of the density grid inside field cell (i, j, k) along one axis.
int inside(int cell, int shift, int n) { return std::min(n - (cell << shift), 1 << shift); }

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
  field.coeffs.assign(bands.size(), {});
  field.response.assign(bands.size(), {});
  field.response_tau_max.assign(bands.size(), 0.0f);
  DiffuseBakeStats st;
  st.noise.assign(bands.size(), -1.0);
  const MajorantGrid majorant = build_majorant_grid(density, o.majorant_block);
  const int n_coeffs = field.n_coeffs();
  const GridShape& cells = field.cells;
  const GridShape& grid = density.shape;
  const double edge = cells.voxel, voxel3 = double(grid.voxel) * grid.voxel * grid.voxel;
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
    const DiffusePassResult pass =
        backend == Backend::Cuda ? diffuse_pass_cuda(in, o.photons) : diffuse_pass_cpu(in, o.photons, progress);
    st.seconds += pass.seconds;
    st.photons += o.photons;
    st.counters.collisions += pass.counters.collisions;
    st.counters.tentative += pass.counters.tentative;
    st.counters.crossings += pass.counters.crossings;
    st.counters.capped += pass.counters.capped;
    st.work_bytes = std::max(st.work_bytes, (pass.sums.size() + pass.odd.size()) * sizeof(unsigned long long) +
                                                pass.device_bytes);
    // Sums of weight x (chord / edge) x Y, each weight in units of the total
    // power / photons: L_k = sum x (power / photons) x edge / (volume inside the grid).
    const double unit = total / double(o.photons) * edge / kDiffuseFixedScale;
    std::vector<float>& c = field.coeffs[b];
    c.assign(pass.sums.size(), 0.0f);
    double noise2 = 0, signal2 = 0;
    for (int z = 0; z < cells.nz; ++z)
      for (int y = 0; y < cells.ny; ++y)
        for (int x = 0; x < cells.nx; ++x) {
          const size_t cell = cells.index(x, y, z);
          const double volume = voxel3 * inside(x, field.shift, grid.nx) * inside(y, field.shift, grid.ny) *
                                inside(z, field.shift, grid.nz);
          for (int k = 0; k < n_coeffs; ++k) {
            const size_t i = cell * size_t(n_coeffs) + size_t(k);
            c[i] = static_cast<float>(double(static_cast<long long>(pass.sums[i])) * unit / volume);
          }
          // The even and odd photons' l = 0 parts are two independent halves.
          const double all = double(static_cast<long long>(pass.sums[cell * size_t(n_coeffs)]));
          const double odd = double(static_cast<long long>(pass.odd[cell]));
          noise2 += (all - 2 * odd) * (all - 2 * odd) / (volume * volume);
          signal2 += all * all / (volume * volume);
        }
    st.noise[b] = signal2 > 0 ? std::sqrt(noise2 / signal2) : 0.0;
    field.response[b] = delta_m_response(*band.table, o.degree);
    field.response_tau_max[b] = static_cast<float>(band.table->tau_max());
  }
  field.pack();
  st.field_bytes = field.bytes();
  if (stats) *stats = st;
  return field;
}

}  // namespace nebula
