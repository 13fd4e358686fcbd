#include "montecarlo/table_conversion.h"

namespace nebula {

namespace {
constexpr const char* kGenerator = "nebula 0.1.0";
}  // namespace

ScatteringTable to_table(const Tabulation& t) {
  const TabulateParams& p = t.params;
  ScatteringTable table = ScatteringTable::make_axes(p.tau_max, p.tau_bins, p.binning, p.mu_bins);
  table.albedo = p.albedo;
  table.g = p.g;
  table.illumination = to_string(p.beam);
  table.photons_per_row = p.photons_per_row;
  table.thin_boost = uint64_t(p.thin_boost);
  table.seed = p.seed;
  table.generator = kGenerator;
  table.forced_first_scattering = p.forced_first_scattering;
  table.roulette_threshold = p.roulette.threshold;
  table.roulette_survival = p.roulette.survival;
  table.max_orders = p.roulette.max_orders;
  table.capped_photons = t.capped_photons;
  table.scattering_events = t.scattering_events;
  for (size_t e = 0; e < t.P.size(); ++e) {
    table.P[e] = static_cast<float>(t.P[e]);
    table.P_stderr[e] = static_cast<float>(t.P_stderr[e]);
  }
  table.total = t.total;
  table.total_stderr = t.total_stderr;
  table.unscattered = t.unscattered;
  return table;
}

}  // namespace nebula
