#include "tables/table_lookup.h"

#include <string>

#include "core/error.h"
#include "tables/scattering_table.h"

namespace nebula {

std::vector<float> cumulative_rows(const ScatteringTable& table) {
  const int n_tau = table.n_tau(), n_mu = table.n_mu();
  std::vector<float> c(table.P.size());
  if (table.P.size() != size_t(n_tau) * n_mu) return c;  // view_of refuses such a table
  for (int i = 0; i < n_tau; ++i) {
    const float* p = table.P.data() + table.index(i, 0);
    double sum = 0.5 * p[0];
    for (int k = 0; k < n_mu; ++k) {
      if (k > 0) sum += 0.5 * (double(p[k - 1]) + p[k]);
      c[table.index(i, k)] = float(sum);
    }
  }
  return c;
}

TableView view_of(const ScatteringTable& table) {
  const size_t cells = static_cast<size_t>(table.n_tau()) * table.n_mu();
  if (table.n_tau() < 2 || table.n_mu() < 1 || table.P.size() != cells)
    throw Error("scattering table: /P: expected " + std::to_string(table.n_tau()) + " x " +
                std::to_string(table.n_mu()) + " values with n_tau >= 2 and n_mu >= 1, found " +
                std::to_string(table.P.size()));
  TableView view;
  view.P = table.P.data();
  view.n_tau = table.n_tau();
  view.n_mu = table.n_mu();
  view.tau_max = static_cast<float>(table.tau_max());
  view.tau_scale = table.tau_max() > 0.0 ? static_cast<float>((table.n_tau() - 1) / table.tau_max()) : 0.0f;
  view.bins = table.bins();
  return view;
}

}  // namespace nebula
