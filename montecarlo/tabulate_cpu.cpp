// CPU backend of the tabulator and the slab: TBB over chunks of photons, the
// photon physics shared with the CUDA kernels.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <vector>

#include "core/progress.h"
#include "montecarlo/slab.h"
#include "montecarlo/tabulate.h"

namespace nebula {
namespace {

constexpr uint64_t kChunk = 2048;  // photons per task

void atomic_add(uint64_t& target, uint64_t v) {
  if (v) std::atomic_ref<uint64_t>(target).fetch_add(v, std::memory_order_relaxed);
}

struct CpuSphereSink {
  std::vector<uint64_t> s1, s2;
  uint64_t capped = 0, capped_weight = 0;
  explicit CpuSphereSink(int n_mu) : s1(n_mu, 0), s2(n_mu, 0) {}
  void add_bin(int k, uint64_t x, uint64_t x2) {
    s1[k] += x;
    s2[k] += x2;
  }
  void add_capped(uint64_t x) {
    ++capped;
    capped_weight += x;
  }
};

}  // namespace

SphereTallies tabulate_sphere_cpu(const TabulateParams& p, Progress* progress) {
  SphereTallies t;
  t.resize(p.tau_bins, p.mu_bins);
  std::vector<SphereRow> rows(p.tau_bins);
  for (int i = 0; i < p.tau_bins; ++i) rows[i] = make_sphere_row(p, i);
  // Tasks of kChunk photons, the heaviest (largest tau) rows first, for a short
  // tail: first_task[j] is the first task of the j-th row in that order.
  std::vector<uint64_t> first_task(p.tau_bins + 1, 0);
  for (int j = 0; j < p.tau_bins; ++j)
    first_task[j + 1] = first_task[j] + (rows[p.tau_bins - 1 - j].photons + kChunk - 1) / kChunk;
  const uint64_t tasks = first_task.back();
  const auto start = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, tasks, 1), [&](const auto& range) {
    for (uint64_t task = range.begin(); task != range.end(); ++task) {
      const int j = static_cast<int>(std::upper_bound(first_task.begin(), first_task.end(), task) - first_task.begin()) - 1;
      const int i = p.tau_bins - 1 - j;
      const SphereRow& row = rows[i];
      const uint64_t begin = (task - first_task[j]) * kChunk;
      const uint64_t end = std::min<uint64_t>(begin + kChunk, row.photons);
      CpuSphereSink sink(p.mu_bins);
      uint64_t unscattered = 0, events = 0;
      for (uint64_t photon = begin; photon < end; ++photon) {
        const auto id = static_cast<uint32_t>(photon);
        PhotonState st;
        Fate f = Fate::Flying;
        while (f == Fate::Flying) {
          float left_unscattered;
          f = sphere_step(row, id, st, left_unscattered);
          unscattered += to_fixed(left_unscattered);
        }
        events += st.orders;
        tally_sphere_photon(row, st, f, sink);
      }
      for (int k = 0; k < p.mu_bins; ++k) {
        atomic_add(t.sum_w[size_t(i) * p.mu_bins + k], sink.s1[k]);
        atomic_add(t.sum_w2[size_t(i) * p.mu_bins + k], sink.s2[k]);
      }
      atomic_add(t.unscattered[i], unscattered);
      atomic_add(t.events[i], events);
      atomic_add(t.capped[i], sink.capped);
      atomic_add(t.capped_weight[i], sink.capped_weight);
      if (progress) progress->add(end - begin);
    }
  });
  t.compute_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

SlabTallies simulate_slab_cpu(const SlabParams& p, Progress* progress) {
  const SlabRun run = make_slab_run(p);
  SlabTallies total;
  const uint64_t tasks = (p.photons + kChunk - 1) / kChunk;
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, tasks, 1), [&](const auto& range) {
    for (uint64_t task = range.begin(); task != range.end(); ++task) {
      const uint64_t begin = task * kChunk, end = std::min(begin + kChunk, p.photons);
      SlabTallies local;
      for (uint64_t photon = begin; photon < end; ++photon)
        run_slab_photon(run, static_cast<uint32_t>(photon), local);
      atomic_add(total.sum_r, local.sum_r);
      atomic_add(total.sum_r2, local.sum_r2);
      atomic_add(total.sum_t, local.sum_t);
      atomic_add(total.sum_t2, local.sum_t2);
      atomic_add(total.unscattered, local.unscattered);
      atomic_add(total.events, local.events);
      atomic_add(total.capped, local.capped);
      atomic_add(total.capped_weight, local.capped_weight);
      if (progress) progress->add(end - begin);
    }
  });
  return total;
}

}  // namespace nebula
