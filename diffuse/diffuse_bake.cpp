#include "diffuse/diffuse_bake.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
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
  if (o.zonal != 0 && (o.zonal <= o.degree || o.zonal > kMaxZonalDegree))
    throw ParameterError("diffuse_zonal", "must be 0 (none) or " + std::to_string(o.degree + 1) + " to " +
                                              std::to_string(kMaxZonalDegree) + " (above diffuse_order), got " +
                                              std::to_string(o.zonal));
  if (o.shared_order_buckets < -1 || o.shared_order_buckets > kMaxOrderBuckets)
    throw ParameterError("shared_order_buckets", "must be -1 (auto) or 0 to " + std::to_string(kMaxOrderBuckets) +
                                                     ", got " + std::to_string(o.shared_order_buckets));
}

// The relative L2 noise of a band's l = 0 field from its two halves: the
// even and odd photons' sums are independent estimates. Slot `slot` of sums
// laid out [cell * slots + slot].
double field_noise(const std::vector<double>& l0, const std::vector<double>& odd, size_t slots, size_t slot,
                   const GridShape& cells, const GridShape& grid, int shift) {
  double noise2 = 0, signal2 = 0;
  for (int z = 0; z < cells.nz; ++z)
    for (int y = 0; y < cells.ny; ++y)
      for (int x = 0; x < cells.nx; ++x) {
        const size_t cell = cells.index(x, y, z);
        const double volume = diffuse_cell_volume(grid, shift, x, y, z);
        diffuse_cell_noise(l0[cell * slots + slot], odd[cell * slots + slot], volume, noise2, signal2);
      }
  return signal2 > 0 ? std::sqrt(noise2 / signal2) : 0.0;
}

}  // namespace

int shared_order_buckets_for(const DiffuseBakeOptions& o, Backend backend, size_t cells, int n_coeffs) {
  if (o.shared_order_buckets >= 0) return o.shared_order_buckets;
  if (backend != Backend::Cuda) return 8;
  const size_t bucket = std::max<size_t>(1, cells * size_t(n_coeffs) * sizeof(unsigned long long));
  return int(std::clamp<size_t>(kSharedBucketBytes / bucket, 8, kMaxOrderBuckets));
}

DiffuseSlots diffuse_slots(const DiffusePassInputs& in, size_t cells, int n_coeffs) {
  DiffuseSlots l;
  l.cells = cells;
  l.n_coeffs = n_coeffs;
  l.slots = in.slots();
  l.buckets = l.slots > 1 ? in.order_buckets : 0;
  for (int k = 0; k < l.slots && !in.slot_albedos.empty(); ++k)
    l.scale[k] = in.slot_albedos[size_t(k)] == in.band.albedo ? 1.0 : double(in.slot_albedos[size_t(k)]) / in.band.albedo;
  return l;
}

DiffusePassResult diffuse_pass_cpu(const DiffusePassInputs& in, uint64_t photons, Progress* progress) {
  HostPlacement host;
  const DiffusePhotonScene scene = assemble_photon_scene(in, host);
  DiffusePassResult out;
  DiffuseSlots layout = diffuse_slots(in, in.cells.count(), scene.n_coeffs);
  out.sums.assign(layout.entries(), 0ull);
  layout.n_coeffs = 1;
  out.odd.assign(layout.entries(), 0ull);
  // Each thread adds into sums of its own when they fit the budget (plain
  // adds: a locked add costs some 20 times more, and a crossing makes 16 per
  // albedo), else into the shared ones atomically. Integer sums: the same
  // totals either way, in any order.
  const size_t threads = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  const size_t entries = out.sums.size() + out.odd.size();
  const bool private_sums = threads * entries * sizeof(unsigned long long) <= in.private_sums_bytes;
  tbb::enumerable_thread_specific<std::vector<unsigned long long>> local(
      [&] { return std::vector<unsigned long long>(entries, 0ull); });
  unsigned long long* sums = out.sums.data();
  unsigned long long* odd = out.odd.data();
  const size_t odd_at = out.sums.size();
  std::mutex counters_lock;
  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, photons, 1024), [&](const auto& range) {
    PhotonCounters c;
    auto trace = [&](auto&& deposit, auto&& deposit_odd) {
      for (uint64_t p = range.begin(); p != range.end(); ++p) {
        const uint32_t i = static_cast<uint32_t>(p);
        if (scene.slots > 1 && scene.zonal > 0)
          trace_diffuse_photon<true, true>(scene, i, deposit, deposit_odd, c);
        else if (scene.slots > 1)
          trace_diffuse_photon<true, false>(scene, i, deposit, deposit_odd, c);
        else if (scene.zonal > 0)
          trace_diffuse_photon<false, true>(scene, i, deposit, deposit_odd, c);
        else
          trace_diffuse_photon<false, false>(scene, i, deposit, deposit_odd, c);
      }
    };
    if (private_sums) {
      unsigned long long* mine = local.local().data();
      trace([&](size_t i, unsigned long long v) { mine[i] += v; },
            [&](size_t i, unsigned long long v) { mine[odd_at + i] += v; });
    } else {
      trace([&](size_t i, unsigned long long v) { __atomic_fetch_add(&sums[i], v, __ATOMIC_RELAXED); },
            [&](size_t i, unsigned long long v) { __atomic_fetch_add(&odd[i], v, __ATOMIC_RELAXED); });
    }
    {
      std::lock_guard<std::mutex> lock(counters_lock);
      out.counters.collisions += c.collisions;
      out.counters.tentative += c.tentative;
      out.counters.crossings += c.crossings;
      out.counters.capped += c.capped;
    }
    if (progress) progress->add(range.size());
  });
  if (private_sums) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, entries, 1 << 16), [&](const auto& r) {
      for (const std::vector<unsigned long long>& mine : local)
        for (size_t i = r.begin(); i != r.end(); ++i) {
          if (i < odd_at)
            sums[i] += mine[i];
          else
            odd[i - odd_at] += mine[i];
        }
    });
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.host_bytes = (entries + (private_sums ? local.size() * entries : 0)) * sizeof(unsigned long long);
  return out;
}

namespace {

// The sets may differ in albedos and tables only: one pass serves them all.
void check_sets(const std::vector<std::vector<DiffuseBand>>& sets, const std::vector<StarLight>& stars) {
  if (sets.empty() || sets.size() > size_t(kMaxAlbedoSlots))
    throw Error("diffuse bake: 1 to " + std::to_string(kMaxAlbedoSlots) + " sets of bands per shared pass");
  const std::vector<DiffuseBand>& first = sets.front();
  if (first.empty() || first.size() > size_t(kMaxBands))
    throw Error("diffuse bake: 1 to " + std::to_string(kMaxBands) + " bands required");
  for (const StarLight& s : stars)
    if (s.power.size() != first.size()) throw Error("diffuse bake: a star lacks band powers");
  for (const std::vector<DiffuseBand>& set : sets) {
    if (set.size() != first.size()) throw Error("diffuse bake: shared sets with different band counts");
    for (size_t b = 0; b < set.size(); ++b) {
      const DiffuseBand& band = set[b];
      if (band.albedo > 0 && !band.table) throw Error("diffuse bake: band " + band.name + " scatters but has no table");
      if (!(band.albedo >= 0 && band.albedo <= 1))
        throw Error("diffuse bake: band " + band.name + " has albedo " + std::to_string(band.albedo));
      if (band.name != first[b].name || band.extinction_ratio != first[b].extinction_ratio || band.g != first[b].g)
        throw Error("diffuse bake: shared sets differ in band " + band.name + " beyond its albedo");
    }
  }
}

}  // namespace

DiffuseField bake_diffuse(const DensityGrid& density, const std::vector<DiffuseBand>& bands,
                          const std::vector<StarLight>& stars, const DiffuseBakeOptions& o, Backend backend,
                          DiffuseBakeStats* stats, Progress* progress) {
  std::vector<DiffuseBakeStats> all;
  std::vector<DiffuseField> fields = bake_diffuse_shared(density, {bands}, stars, o, backend, &all, progress);
  if (stats) *stats = all.front();
  return std::move(fields.front());
}

std::vector<DiffuseField> bake_diffuse_shared(const DensityGrid& density,
                                              const std::vector<std::vector<DiffuseBand>>& sets,
                                              const std::vector<StarLight>& stars, const DiffuseBakeOptions& o,
                                              Backend backend, std::vector<DiffuseBakeStats>* stats,
                                              Progress* progress) {
  check_options(o);
  check_sets(sets, stars);
  const size_t n_sets = sets.size(), n_bands = sets.front().size();
  std::vector<DiffuseField> fields(n_sets);
  // The zonal stars: the brightest, by their total power over the bands (the stars keep their order).
  std::vector<size_t> zonal_order(stars.size());
  for (size_t i = 0; i < stars.size(); ++i) zonal_order[i] = i;
  auto total_power = [&](size_t i) {
    double t = 0;
    for (float p : stars[i].power) t += std::max(0.0f, p);
    return t;
  };
  if (o.zonal > 0)  // else the photons' stars as given: the same field as without the option
    std::stable_sort(zonal_order.begin(), zonal_order.end(),
                     [&](size_t a, size_t b) { return total_power(a) > total_power(b); });
  const int zonal_stars = o.zonal > 0 ? int(std::min(stars.size(), size_t(kMaxZonalStars))) : 0;
  std::vector<StarLight> ordered;  // the zonal stars first
  for (size_t i : zonal_order) ordered.push_back(stars[i]);
  for (DiffuseField& f : fields) {
    f.degree = o.degree;
    f.cells = diffuse_cells(density.shape, o.cells, &f.shift);
    f.zonal = o.zonal;
    f.zonal_stars = zonal_stars;
    for (int k = 0; k < zonal_stars; ++k) f.zonal_star[k] = ordered[size_t(k)].position;
  }
  const DiffuseField& shape = fields.front();
  std::vector<DiffuseBakeStats> st(n_sets);
  for (DiffuseBakeStats& s : st) s.noise.assign(n_bands, -1.0);
  const MajorantGrid majorant = build_majorant_grid(density, o.majorant_block);
  const int n_coeffs = shape.n_coeffs();
  const GridShape& cells = shape.cells;
  const GridShape& grid = density.shape;
  // One pass per band that scatters light from a star in some set, traced at
  // the band's largest albedo over the sets.
  std::vector<DiffusePassInputs> passes;
  std::vector<double> units;
  for (size_t b = 0; b < n_bands; ++b) {
    float largest = 0;
    for (const std::vector<DiffuseBand>& set : sets) largest = std::max(largest, set[b].albedo);
    if (!(largest > 0) || stars.empty()) continue;
    double total = 0;
    for (const StarLight& s : stars) total += std::max(0.0f, s.power[b]);
    if (!(total > 0)) continue;
    DiffusePassInputs in;
    in.density = &density;
    in.majorant = &majorant;
    double running = 0;
    for (const StarLight& s : ordered) {
      in.stars.push_back(s.position);
      running += std::max(0.0f, s.power[b]);
      in.star_cdf.push_back(static_cast<float>(running / total));
    }
    in.star_cdf.back() = 1.0f;
    in.band = sets.front()[b];
    in.band.albedo = largest;
    if (n_sets > 1)
      for (const std::vector<DiffuseBand>& set : sets) in.slot_albedos.push_back(set[b].albedo);
    in.band_index = static_cast<uint32_t>(b);
    in.stream = o.common_streams ? 0u : in.band_index;
    in.cells = cells;
    in.degree = o.degree;
    in.zonal = o.zonal;
    in.zonal_stars = zonal_stars;
    in.seed = o.seed;
    in.roulette_start = o.roulette_start;
    in.max_orders = o.max_orders;
    in.private_sums_bytes = o.private_sums_bytes;
    in.order_buckets = shared_order_buckets_for(o, backend, cells.count(), n_coeffs);
    passes.push_back(std::move(in));
    // Sums of weight x (chord / edge) x Y, each weight in units of the total
    // power / photons: L_k = sum x (power / photons) x edge / (volume inside the grid).
    units.push_back(total / double(o.photons) * cells.voxel / kDiffuseFixedScale);
  }
  std::vector<DiffusePassResult> results;
  const bool on_device = backend == Backend::Cuda && !passes.empty();
  for (DiffuseField& f : fields) f.allocate(n_bands, /*on_host=*/!on_device);
  if (on_device) {
    std::vector<DiffuseField*> targets;
    for (DiffuseField& f : fields) targets.push_back(&f);
    results = diffuse_passes_cuda(passes, units, o.photons, grid, targets);
  } else {
    std::vector<float*> packed;
    for (DiffuseField& f : fields) packed.push_back(f.packed_for_writing().data());
    for (size_t p = 0; p < passes.size(); ++p) {
      DiffusePassResult pass = diffuse_pass_cpu(passes[p], o.photons, progress);
      const size_t b = passes[p].band_index;
      const DiffuseSlots layout = diffuse_slots(passes[p], cells.count(), n_coeffs);
      DiffuseSlots odd_layout = layout;
      odd_layout.n_coeffs = 1;
      pass.l0.resize(cells.count() * n_sets);
      pass.odd_l0.resize(cells.count() * n_sets);
      tbb::parallel_for(0, cells.nz, [&](int z) {
        for (int y = 0; y < cells.ny; ++y)
          for (int x = 0; x < cells.nx; ++x) {
            const size_t cell = cells.index(x, y, z);
            const double volume = diffuse_cell_volume(grid, shape.shift, x, y, z);
            for (size_t s = 0; s < n_sets; ++s) {
              for (int k = 0; k < n_coeffs; ++k) {
                const size_t i = cell * size_t(n_coeffs) + size_t(k);
                packed[s][i * 4 + b] =
                    diffuse_coefficient(layout.sum(pass.sums.data(), int(s), cell, k), units[p], volume);
              }
              pass.l0[cell * n_sets + s] = layout.sum(pass.sums.data(), int(s), cell, 0);
              pass.odd_l0[cell * n_sets + s] = odd_layout.sum(pass.odd.data(), int(s), cell, 0);
            }
          }
      });
      pass.sums = {};
      pass.odd = {};
      results.push_back(std::move(pass));
    }
  }
  // Responses, shared between bands and sets with one table.
  std::vector<std::pair<const ScatteringTable*, const std::vector<float>*>> responses;
  for (size_t p = 0; p < passes.size(); ++p) {
    const DiffusePassResult& pass = results[p];
    const size_t b = passes[p].band_index;
    for (size_t s = 0; s < n_sets; ++s) {
      DiffuseBakeStats& stat = st[s];
      stat.seconds += pass.seconds;
      stat.photons += o.photons;
      stat.counters.collisions += pass.counters.collisions;
      stat.counters.tentative += pass.counters.tentative;
      stat.counters.crossings += pass.counters.crossings;
      stat.counters.capped += pass.counters.capped;
      stat.work_bytes = std::max(stat.work_bytes, pass.host_bytes + pass.device_bytes);
      const DiffuseBand& band = sets[s][b];
      DiffuseField& field = fields[s];
      if (!(band.albedo > 0)) continue;  // this set's band scatters nothing: no field, as a bake of its own
      if (!pass.noise2.empty())
        stat.noise[b] = pass.signal2[s] > 0 ? std::sqrt(pass.noise2[s] / pass.signal2[s]) : 0.0;
      else
        stat.noise[b] = field_noise(pass.l0, pass.odd_l0, n_sets, s, cells, grid, field.shift);
      const std::vector<float>* known = nullptr;
      for (const auto& [table, response] : responses)
        if (table == band.table) known = response;
      if (known) {
        field.response[b] = *known;
      } else {
        field.response[b] = delta_m_response(*band.table, o.degree, o.zonal, o.taper);
        responses.emplace_back(band.table, &field.response[b]);
      }
      field.response_tau_max[b] = static_cast<float>(band.table->tau_max());
    }
  }
  for (size_t s = 0; s < n_sets; ++s) st[s].field_bytes = fields[s].bytes();
  if (stats) *stats = std::move(st);
  return fields;
}

}  // namespace nebula
