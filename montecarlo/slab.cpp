#include "montecarlo/slab.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/gpu.h"
#include "core/math.h"
#include "montecarlo/tabulate.h"

namespace nebula {

void validate(const SlabParams& p) {
  if (!(p.albedo >= 0.0 && p.albedo <= 1.0))
    throw ParameterError("albedo", "must be in [0, 1], got " + to_text(p.albedo));
  if (!(std::fabs(p.g) < 1.0)) throw ParameterError("g", "|g| must be below 1, got " + to_text(p.g));
  if (!(p.tau > 0.0) || std::isnan(p.tau))
    throw ParameterError("tau", "must be a positive optical thickness, got " + to_text(p.tau));
  if (!(p.incidence_deg >= 0.0 && p.incidence_deg < 90.0))
    throw ParameterError("incidence_deg", "must be in [0, 90), got " + to_text(p.incidence_deg));
  if (p.photons < 2 || p.photons > kMaxPhotonsPerRow)
    throw ParameterError("photons", "need 2 to 2^30 photons, got " + to_text(double(p.photons)));
}

SlabRun make_slab_run(const SlabParams& p) {
  SlabRun run{};
  // Thickness in mean free paths; "infinite" slabs are capped where float
  // optical depths stop meaning anything (no photon returns from 1e30).
  run.geometry.thickness = static_cast<float>(std::fmin(p.tau, 1e30));
  run.medium = {1.0f, static_cast<float>(p.albedo), static_cast<float>(p.g)};
  run.roulette = p.roulette;
  run.stream = {p.seed, 0u, kPurposeSlab};
  const double theta = p.incidence_deg * kPiD / 180.0;
  run.source.incident = {static_cast<float>(std::sin(theta)), 0.0f,
                         static_cast<float>(std::cos(theta))};
  run.forced_first = p.forced_first_scattering;
  return run;
}

SlabResult simulate_slab(const SlabParams& p, Backend backend, Progress* progress) {
  validate(p);
  const auto start = std::chrono::steady_clock::now();
  const SlabTallies t =
      backend == Backend::Cuda ? simulate_slab_cuda(p, progress) : simulate_slab_cpu(p, progress);
  SlabResult r;
  r.params = p;
  const double n = static_cast<double>(p.photons);
  auto mean_and_error = [n](uint64_t s1, uint64_t s2, double& mean, double& err) {
    mean = from_fixed(s1) / n;
    err = std::sqrt(std::fmax(from_fixed(s2) / n - mean * mean, 0.0) / (n - 1));
  };
  mean_and_error(t.sum_r, t.sum_r2, r.R_diffuse, r.R_stderr);
  mean_and_error(t.sum_t, t.sum_t2, r.T_total, r.T_stderr);
  const double mu0 = std::cos(p.incidence_deg * kPiD / 180.0);
  r.T_unscattered = std::exp(-p.tau / mu0);
  r.scattering_events = t.events;
  r.capped_photons = t.capped;
  r.capped_weight = from_fixed(t.capped_weight) / n;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.device = backend == Backend::Cuda ? gpu_description() : "cpu (TBB)";
  return r;
}

}  // namespace nebula
