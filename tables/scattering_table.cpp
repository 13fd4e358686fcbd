#include "tables/scattering_table.h"

#include <algorithm>

#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/math.h"

namespace nebula {

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

// One checker per table so every message has the same "SOURCE: FIELD: " head.
struct Checker {
  const std::string& source;

  [[noreturn]] void fail(const std::string& field, const std::string& expected,
                         const std::string& found) const {
    throw Error(source + ": " + field + ": expected " + expected + ", found " + found);
  }

  void size(const std::string& field, size_t found, size_t expected,
            const std::string& why) const {
    if (found != expected)
      fail(field, std::to_string(expected) + " values (" + why + ")",
           std::to_string(found));
  }

  void string_is(const std::string& field, const std::string& found,
                 const std::string& expected) const {
    if (found != expected) fail(field, quoted(expected), quoted(found));
  }

  // Finite, >= 0 and <= upper; `columns` > 0 reports a 2-D position [i][k].
  template <class T>
  void in_range(const std::string& field, const std::vector<T>& values, double upper,
                const std::string& expected, size_t columns = 0) const {
    for (size_t j = 0; j < values.size(); ++j) {
      const double v = values[j];
      if (std::isfinite(v) && v >= 0.0 && v <= upper) continue;
      char at[64];
      if (columns > 0)
        std::snprintf(at, sizeof at, " at [%zu][%zu]", j / columns, j % columns);
      else
        std::snprintf(at, sizeof at, " at [%zu]", j);
      fail(field, expected, number(v) + at);
    }
  }
};

}  // namespace

ScatteringTable ScatteringTable::make_axes(double tau_max, int n_tau, AngularBinning binning,
                                           int n_mu) {
  if (!(tau_max > 0.0) || !std::isfinite(tau_max))
    throw Error("scattering table: tau_max: expected a finite value > 0, found " + number(tau_max));
  if (n_tau < 2)
    throw Error("scattering table: n_tau: expected >= 2 rows, found " + std::to_string(n_tau));
  if (n_mu < 1)
    throw Error("scattering table: n_mu: expected >= 1 bins, found " + std::to_string(n_mu));

  ScatteringTable t;
  t.mu_binning = binning;
  t.tau.resize(n_tau);
  for (int i = 0; i < n_tau; ++i) t.tau[i] = tau_max * i / (n_tau - 1);
  t.tau.back() = tau_max;  // exact, whatever the rounding of the product

  const AngularBins bins{binning, n_mu};
  t.mu_edges.resize(n_mu + 1);
  for (int k = 0; k <= n_mu; ++k) t.mu_edges[k] = bins.edge(k);
  t.mu.resize(n_mu);
  for (int k = 0; k < n_mu; ++k) t.mu[k] = bins.centre(k);

  const size_t cells = static_cast<size_t>(n_tau) * n_mu;
  t.P.assign(cells, 0.0f);
  t.P_stderr.assign(cells, 0.0f);
  t.total.assign(n_tau, 0.0);
  t.total_stderr.assign(n_tau, 0.0);
  t.unscattered.assign(n_tau, 0.0);
  return t;
}

double ScatteringTable::median_relative_error() const {
  std::vector<double> r;
  r.reserve(P.size());
  for (size_t i = 0; i < P.size() && i < P_stderr.size(); ++i)
    if (P[i] > 0.0f) r.push_back(double(P_stderr[i]) / double(P[i]));
  if (r.empty()) return 0.0;
  std::nth_element(r.begin(), r.begin() + long(r.size() / 2), r.end());
  return r[r.size() / 2];
}

double ScatteringTable::total_from_P(int i_tau) const {
  const AngularBins b = bins();
  double sum = 0.0;
  for (int k = 0; k < n_mu(); ++k) sum += static_cast<double>(P[index(i_tau, k)]) * b.solid_angle(k);
  // The voxel edge l is 1: P is per voxel face area, the sphere's cross-section is pi R^2.
  return sum / (kPiD * kVoxelSphereRadius * kVoxelSphereRadius);
}

void ScatteringTable::check_consistency(const std::string& source) const {
  const Checker c{source};

  // Provenance and physics parameters.
  c.string_is("phase", phase, "henyey-greenstein");
  c.string_is("geometry", geometry, "sphere");
  if (illumination != "parallel" && illumination != "pencil")
    c.fail("illumination", "\"parallel\" or \"pencil\"", quoted(illumination));
  c.string_is("rng", rng, "philox4x32-10");
  if (schema_version != 1) c.fail("schema_version", "1", std::to_string(schema_version));
  if (generator.empty())
    c.fail("generator", "the name and version of the program that made the table",
           "an empty string");
  if (!(albedo >= 0.0 && albedo <= 1.0)) c.fail("albedo", "a value in [0, 1]", number(albedo));
  if (!(std::fabs(g) < 1.0)) c.fail("g", "a value with |g| < 1", number(g));
  if (photons_per_row < 1) c.fail("photons_per_row", ">= 1", "0");
  if (thin_boost < 1) c.fail("thin_boost", ">= 1", "0");
  if (!std::isfinite(roulette_threshold) || roulette_threshold < 0.0)
    c.fail("roulette_threshold", "a finite value >= 0", number(roulette_threshold));
  if (!std::isfinite(roulette_survival) || roulette_survival < 0.0)
    c.fail("roulette_survival", "a finite value >= 0", number(roulette_survival));
  if (mu_binning != AngularBinning::UniformMu && mu_binning != AngularBinning::UniformTheta)
    c.fail("mu_binning", "\"uniform-mu\" or \"uniform-theta\"",
           "enum value " + std::to_string(static_cast<int>(mu_binning)));

  // The tau axis: uniform from 0, at least two rows so rows can be interpolated.
  const size_t nt = tau.size(), nm = mu.size();
  if (nt < 2) c.fail("/tau", "at least 2 values", std::to_string(nt));
  const double tmax = tau.back();
  if (!std::isfinite(tmax) || !(tmax > 0.0))
    c.fail("/tau", "a last value (tau_max) that is finite and > 0", number(tmax));
  for (size_t i = 0; i < nt; ++i) {
    const double expected = tmax * static_cast<double>(i) / static_cast<double>(nt - 1);
    if (!(std::fabs(tau[i] - expected) <= 1e-9 * tmax))
      c.fail("/tau", "uniform values tau_max * i / (n_tau - 1), i.e. " + number(expected) +
                         " at index " + std::to_string(i),
             number(tau[i]));
  }

  // The mu axis: exactly the binning's edges and centres.
  if (nm < 1) c.fail("/mu", "at least 1 bin centre", "0");
  c.size("/mu_edges", mu_edges.size(), nm + 1, "n_mu + 1, from /mu");
  const AngularBins b = bins();
  const std::string binning_name = to_string(mu_binning);
  for (size_t k = 0; k <= nm; ++k)
    if (!(std::fabs(mu_edges[k] - b.edge(static_cast<int>(k))) <= 1e-9))
      c.fail("/mu_edges", binning_name + " edge " + number(b.edge(static_cast<int>(k))) +
                              " at index " + std::to_string(k),
             number(mu_edges[k]));
  for (size_t k = 0; k < nm; ++k)
    if (!(std::fabs(mu[k] - b.centre(static_cast<int>(k))) <= 1e-9))
      c.fail("/mu", binning_name + " bin centre " + number(b.centre(static_cast<int>(k))) +
                        " at index " + std::to_string(k),
             number(mu[k]));

  // Data shapes and ranges.
  c.size("/P", P.size(), nt * nm, "n_tau x n_mu");
  c.size("/P_stderr", P_stderr.size(), nt * nm, "n_tau x n_mu");
  c.size("/total", total.size(), nt, "n_tau");
  c.size("/total_stderr", total_stderr.size(), nt, "n_tau");
  c.size("/unscattered", unscattered.size(), nt, "n_tau");
  const double inf = INFINITY;
  const double fraction_max = 1.0 + 1e-6;
  c.in_range("/P", P, inf, "finite values >= 0", nm);
  c.in_range("/P_stderr", P_stderr, inf, "finite values >= 0", nm);
  c.in_range("/total", total, fraction_max, "fractions in [0, 1]");
  c.in_range("/total_stderr", total_stderr, inf, "finite values >= 0");
  c.in_range("/unscattered", unscattered, fraction_max, "fractions in [0, 1]");

  // total is P integrated over the sphere; P is float32, hence the tolerance.
  for (size_t i = 0; i < nt; ++i) {
    const double from_P = total_from_P(static_cast<int>(i));
    if (!(std::fabs(total[i] - from_P) <= 1e-4 * std::fabs(from_P) + 1e-6))
      c.fail("/total", "sum_k P[i][k] * solid_angle(k) / (pi R^2) = " + number(from_P) +
                           " at row " + std::to_string(i) + " (relative tolerance 1e-4)",
             number(total[i]));
  }
}

}  // namespace nebula
