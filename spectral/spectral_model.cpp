#include "spectral/spectral_model.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <Eigen/Dense>

#include "core/error.h"
#include "illumination/filters.h"

namespace nebula::spectral {
namespace {

constexpr double kTransmittanceCut = 9.210340371976184;  // -ln(1e-4), the marcher's cut
constexpr double kMinTemperature = 2000.0, kMaxTemperature = 60000.0;

// 5-point Gauss-Legendre on [a, b].
template <class F>
double gauss5(F&& f, double a, double b) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                              0.2369268850561891};
  const double m = 0.5 * (a + b), h = 0.5 * (b - a);
  double s = 0.0;
  for (int i = 0; i < 5; ++i) s += w[i] * f(m + h * x[i]);
  return s * h;
}

// V-filter averages of 1/lambda and of the law (kappa's normalisations).
double mean_over_v(const std::function<double(double)>& f) {
  const Passband v = load_filter("V");
  const double num = passband_integral(v, [&](double nm) { return f(nm / 1000.0); }, kPassbandSubdivisions);
  const double den = passband_integral(v, [](double) { return 1.0; }, kPassbandSubdivisions);
  return num / den;
}

// The table's nodes (SpectralSettings::table_nodes) over [kappa_min, kappa_max]
// and the inverse of their Vandermonde matrix: P / kappa at the nodes to the
// coefficients of its interpolating polynomial in kappa.
void set_table_nodes(SpectralModel& m, int nodes, double kappa_min, double kappa_max) {
  m.node_kappa.clear();
  m.node_to_power.clear();
  m.kappa_center = 0.0;
  m.n_powers = std::max(nodes, 1);
  if (nodes == 0) return;
  if (nodes == 1) {
    m.node_kappa = {std::clamp(1.0, kappa_min, kappa_max)};
    m.node_to_power = {1.0};
    return;
  }
  for (int k = 0; k < nodes; ++k) m.node_kappa.push_back(kappa_min + (kappa_max - kappa_min) * k / (nodes - 1));
  m.kappa_center = 0.5 * (kappa_min + kappa_max);
  // V[k][p] = (kappa_k - kappa_c)^p (distinct nodes, at most 4: well posed); row p of V^-1
  // gives the coefficient of (kappa - kappa_c)^p.
  Eigen::MatrixXd V(nodes, nodes);
  for (int k = 0; k < nodes; ++k)
    for (int p = 0; p < nodes; ++p) V(k, p) = std::pow(m.node_kappa[k] - m.kappa_center, p);
  const Eigen::MatrixXd inverse = V.fullPivLu().inverse();
  for (int p = 0; p < nodes; ++p)
    for (int k = 0; k < nodes; ++k) m.node_to_power.push_back(inverse(p, k));
}

void build_emission(SpectralModel& m);
void add_emission_resolve(SpectralModel& m);

// Emission components checked against the model's range, their continua's
// ranges resolved (0, 0: the basis' range; clipped to it).
std::vector<SpectralEmission> checked_emission(const SpectralModel& m, std::vector<SpectralEmission> emission) {
  const auto nm = [](double um) { return to_text(um * 1000.0); };
  const std::string span = "[" + nm(m.lo_um) + ", " + nm(m.hi_um) + "] nm";
  if (emission.size() > size_t(kMaxEmission))
    throw Error("spectral.emission: " + std::to_string(emission.size()) + " components; at most " +
                std::to_string(kMaxEmission));
  for (size_t i = 0; i < emission.size(); ++i) {
    SpectralEmission& e = emission[i];
    const std::string key = "spectral.emission." + std::to_string(i);
    if (e.line_um > 0) {
      if (e.line_um < m.lo_um || e.line_um > m.hi_um)
        throw Error(key + ".line_nm: " + nm(e.line_um) + " nm is outside the filters' span " + span +
                    " (the basis' range: spectral.range_um widens it)");
      continue;
    }
    if (e.continuum.empty()) throw Error(key + ": neither a line nor a continuum");
    const bool given = e.lo_um > 0 || e.hi_um > 0;
    const double lo = given ? std::max(e.lo_um, m.lo_um) : m.lo_um, hi = given ? std::min(e.hi_um, m.hi_um) : m.hi_um;
    if (!(lo < hi))
      throw Error(key + ".range_nm: [" + nm(e.lo_um) + ", " + nm(e.hi_um) + "] nm misses the filters' span " + span);
    e.lo_um = lo;
    e.hi_um = hi;
    double largest = 0.0;
    for (int k = 0; k <= 1000; ++k) largest = std::max(largest, std::fabs(e.phi(lo + (hi - lo) * k / 1000.0)));
    for (int k = 0; k <= 1000; ++k) {
      const double l = lo + (hi - lo) * k / 1000.0;
      if (e.phi(l) < -1e-9 * largest)
        throw Error(key + ".continuum: is " + to_text(e.phi(l)) + " at " + nm(l) +
                    " nm; emission cannot be negative on its range");
    }
  }
  return emission;
}

}  // namespace

double SpectralEmission::phi(double lambda) const {
  if (line_um > 0 || lambda < lo_um || lambda > hi_um) return 0.0;
  double v = 0.0, x = 1.0;
  for (double c : continuum) {
    v += c * x;
    x *= lambda;
  }
  return v;
}

double SpectralStar::shape(double lambda) const {
  if (table) return (*table)(lambda);
  return wien ? wien_shape(lambda, temperature_K) : planck_shape(lambda, temperature_K);
}

double SpectralModel::kappa_at(double lambda) const {
  if (settings.attenuation == Attenuation::Inverse) return C_T / lambda;
  return extinction_ratio_at(lambda * 1000.0, settings.R_V, settings.law) / C_T;
}

namespace {
// The curve's value at x: linear between its points, constant beyond them.
double curve_at(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const size_t i = size_t(std::upper_bound(x.begin(), x.end(), at) - x.begin());
  const double t = (at - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + t * (y[i] - y[i - 1]);
}
}  // namespace

double SpectralModel::albedo_at(double lambda) const {
  return curve_at(settings.curve_um, settings.curve_albedo, lambda);
}
double SpectralModel::g_at(double lambda) const { return curve_at(settings.curve_um, settings.curve_g, lambda); }

double SpectralModel::wavelength_of_kappa(double kappa) const {
  size_t best = 0;
  for (size_t i = 1; i < grid.lambda.size(); ++i)
    if (std::fabs(kappa_grid[i] - kappa) < std::fabs(kappa_grid[best] - kappa)) best = i;
  // Between the closest node and the neighbour on the side of kappa, where kappa is monotonic there.
  for (size_t j : {best > 0 ? best - 1 : best, best + 1 < grid.lambda.size() ? best + 1 : best}) {
    const double k0 = kappa_grid[best], k1 = kappa_grid[j];
    if (j != best && (kappa - k0) * (kappa - k1) <= 0.0 && k0 != k1)
      return grid.lambda[best] + (kappa - k0) / (k1 - k0) * (grid.lambda[j] - grid.lambda[best]);
  }
  return grid.lambda[best];
}

namespace {

// Analytic: the breaks every filter, tabulated star and continuum shares: each
// filter's measured rows (its curve is linear between them, so a cubic per
// segment times a smooth spectrum is within ~(h/lambda)^4 of the product), a
// tabulated star's rows and a continuum's ends within the filters' span; and
// each filter's first and last break.
void set_analytic_breaks(SpectralModel& m) {
  std::vector<double> b;
  for (const Passband& p : m.measured)
    for (double nm : p.wavelength_nm) b.push_back(nm / 1000.0);
  const double lo = b.empty() ? 0.0 : *std::min_element(b.begin(), b.end());
  const double hi = b.empty() ? 0.0 : *std::max_element(b.begin(), b.end());
  for (const SpectralStar& star : m.stars)
    if (star.table)
      for (double l : star.table->wavelength_um)
        if (l > lo && l < hi) b.push_back(l);
  for (const SpectralEmission& e : m.emission)
    for (double l : {e.lo_um, e.hi_um})
      if (e.line_um <= 0 && l > lo && l < hi) b.push_back(l);
  std::sort(b.begin(), b.end());
  m.breaks.clear();
  for (double l : b)
    if (m.breaks.empty() || l > m.breaks.back() * (1 + 1e-12)) m.breaks.push_back(l);
  m.break_range.clear();
  for (const Passband& p : m.measured) {
    const auto at = [&](double nm) {
      const double l = nm / 1000.0;
      return int(std::lower_bound(m.breaks.begin(), m.breaks.end(), l * (1 - 1e-12)) - m.breaks.begin());
    };
    m.break_range.push_back(at(p.wavelength_nm.front()));
    m.break_range.push_back(at(p.wavelength_nm.back()));
  }
  m.jumps.clear();
}

// Appends filter f's jumps for fn (zero outside the filter's rows): a least-squares
// cubic on each segment of the shared breaks within them (global powers of lambda),
// and at break j the change c_(j-1) - c_j (c zero beyond the filter's ends).
static_assert(kAnalyticTerms == kMaxPolynomialDegree + 1);
void append_jumps(const SpectralModel& m, int f, const std::function<double(double)>& fn, std::vector<double>& out) {
  const int n = int(m.breaks.size()), j0 = m.break_range[2 * size_t(f)], j1 = m.break_range[2 * size_t(f) + 1];
  const std::vector<double> own(m.breaks.begin() + j0, m.breaks.begin() + j1 + 1);
  const PiecewisePolynomial p = fit_on_breaks(fn, own);
  const size_t base = out.size();
  out.resize(base + size_t(n) * kAnalyticTerms, 0.0);
  const auto c = [&](int seg, int k) {  // segment seg of the shared breaks
    return seg < j0 || seg >= j1 ? 0.0 : p.coefficients[size_t(seg - j0) * kAnalyticTerms + k];
  };
  for (int j = j0; j <= j1; ++j)
    for (int k = 0; k < kAnalyticTerms; ++k) out[base + size_t(j) * kAnalyticTerms + k] = c(j - 1, k) - c(j, k);
}

}  // namespace

SpectralModel build_spectral_model(const std::vector<std::pair<std::string, Passband>>& filters,
                                   const std::vector<SpectralStar>& stars, const SpectralSettings& settings,
                                   const std::vector<SpectralEmission>& emission) {
  if (filters.empty()) throw Error("spectral: no filter");
  if (settings.basis < 1 || settings.basis > 16)
    throw Error("spectral: the basis size is " + std::to_string(settings.basis) + "; must be in 1..16");
  if (!(settings.max_depth >= 0 && std::isfinite(settings.max_depth)))
    throw Error("spectral: max_depth is " + to_text(settings.max_depth) + "; must be >= 0 (0: automatic)");
  if (!(settings.fit_depth >= 0 && std::isfinite(settings.fit_depth)))
    throw Error("spectral: fit_depth is " + to_text(settings.fit_depth) + "; must be >= 0 (0: automatic)");
  if (settings.wavelengths < 2)
    throw Error("spectral: wavelengths is " + std::to_string(settings.wavelengths) + "; must be at least 2");
  for (const SpectralStar& s : stars) {
    if (!s.table && !(s.temperature_K > 0.0 && std::isfinite(s.temperature_K)))
      throw Error("spectral: a star temperature of " + to_text(s.temperature_K) + " K; must be positive");
    if (s.table && settings.method == SpectralMethod::LightBasis)
      throw Error("spectral: the light-density basis spans black bodies; star spectrum '" + s.table->name +
                  "' is tabulated (use the projection method)");
  }
  if (settings.method == SpectralMethod::VoxelLight && stars.size() > size_t(kMaxVoxelLightStars))
    throw Error("spectral: the voxel-light method takes at most " + std::to_string(kMaxVoxelLightStars) + " stars, got " +
                std::to_string(stars.size()));
  if (!(settings.near_voxels >= 0 && std::isfinite(settings.near_voxels)))
    throw Error("spectral: near_voxels is " + to_text(settings.near_voxels) + "; must be >= 0");
  if (settings.table_nodes < 0 || settings.table_nodes > kMaxTableNodes)
    throw Error("spectral: table_nodes is " + std::to_string(settings.table_nodes) + "; must be in 0.." +
                std::to_string(kMaxTableNodes) + " (0: the thin-voxel limit)");
  if (settings.method == SpectralMethod::Analytic && settings.attenuation != Attenuation::Inverse)
    throw Error("spectral: the analytic integral needs the attenuation C_T / lambda (attenuation = \"inverse\")");
  if (!settings.curve_um.empty()) {
    const size_t n = settings.curve_um.size();
    bool ok = settings.curve_albedo.size() == n && settings.curve_g.size() == n;
    for (size_t i = 0; ok && i < n; ++i) ok = settings.curve_um[i] > 0 && (i == 0 || settings.curve_um[i] > settings.curve_um[i - 1]);
    for (double a : settings.curve_albedo) ok = ok && a >= 0 && a <= 1;
    for (double g : settings.curve_g) ok = ok && g > -1 && g < 1;
    if (!ok)
      throw Error("spectral: the albedo and g curves need increasing positive wavelengths, as many values as "
                  "wavelengths, albedos in [0, 1] and |g| < 1");
    if (settings.table_nodes < 1)
      throw Error("spectral: albedo and g varying with wavelength need table_nodes >= 1 (each node its own albedo "
                  "and g)");
  }
  SpectralModel m;
  m.settings = settings;
  m.n_stars = int(stars.size());
  m.stars = stars;
  m.lo_um = 1e30;
  m.hi_um = 0;
  for (const auto& [name, band] : filters) {
    FitReport r;
    m.filter_names.push_back(name);
    m.filters.push_back(fit_passband(band, 2e-3, &r));
    m.fits.push_back(r);
    m.measured.push_back(band);
    m.lo_um = std::min(m.lo_um, band.wavelength_nm.front() / 1000.0);
    m.hi_um = std::max(m.hi_um, band.wavelength_nm.back() / 1000.0);
  }
  if (settings.attenuation == Attenuation::Inverse) {
    m.C_T = 1.0 / mean_over_v([](double l) { return 1.0 / l; });
  } else {
    m.C_T = mean_over_v([&](double l) { return extinction_ratio_at(l * 1000.0, settings.R_V, settings.law); });
    (void)m.kappa_at(m.lo_um);  // a filter outside the law's range is refused here, naming the wavelength
    (void)m.kappa_at(m.hi_um);
  }
  if (settings.lo_um > 0 || settings.hi_um > 0) {
    if (!(settings.lo_um > 0 && settings.hi_um > settings.lo_um && settings.lo_um <= m.lo_um && settings.hi_um >= m.hi_um))
      throw Error("spectral: the wavelength range [" + to_text(settings.lo_um) + ", " + to_text(settings.hi_um) +
                  "] um must hold every filter (they span [" + to_text(m.lo_um) + ", " + to_text(m.hi_um) + "] um)");
    m.lo_um = settings.lo_um;
    m.hi_um = settings.hi_um;
  }
  m.emission = checked_emission(m, emission);
  m.grid = WavelengthGrid::uniform(m.lo_um, m.hi_um, settings.grid_nodes);
  double kappa_min = 1e30, kappa_max = 0;
  for (double l : m.grid.lambda) {
    m.kappa_grid.push_back(m.kappa_at(l));
    kappa_min = std::min(kappa_min, m.kappa_grid.back());
    kappa_max = std::max(kappa_max, m.kappa_grid.back());
  }
  m.max_eye_depth = float(kTransmittanceCut / kappa_min);
  set_table_nodes(m, settings.table_nodes, kappa_min, kappa_max);
  if (m.varying()) {  // each node's (a, g) at a wavelength of its attenuation
    for (double k : m.node_kappa) {
      m.node_lambda.push_back(m.wavelength_of_kappa(k));
      m.node_albedo.push_back(m.albedo_at(m.node_lambda.back()));
      m.node_g.push_back(m.g_at(m.node_lambda.back()));
    }
  }
  m.max_depth = settings.max_depth > 0 ? settings.max_depth : kTransmittanceCut / kappa_min;
  m.fit_depth = settings.fit_depth > 0 ? settings.fit_depth : std::min(kFitDepth, m.max_depth);
  if (!(m.fit_depth <= m.max_depth))
    throw Error("spectral: fit_depth " + to_text(m.fit_depth) + " exceeds max_depth " + to_text(m.max_depth));
  const int F = int(filters.size()), S = int(stars.size()), N = settings.basis;
  std::vector<std::vector<double>> S_on_grid(F);
  for (int f = 0; f < F; ++f)
    for (double l : m.grid.lambda) S_on_grid[f].push_back(m.filters[f](l));

  switch (settings.method) {
    case SpectralMethod::Double: {
      if (F > kMaxAccumulators) throw Error("spectral: at most 64 filters");
      m.n_acc = F;
      const int M = settings.wavelengths;
      const double step = (m.hi_um - m.lo_um) / M;
      for (int i = 0; i < M; ++i) m.kappa.push_back(float(m.kappa_at(m.lo_um + (i + 0.5) * step)));
      if (m.varying())
        for (int i = 0; i < M; ++i) {
          m.lambda_albedo.push_back(float(m.albedo_at(m.lo_um + (i + 0.5) * step)));
          m.lambda_g.push_back(float(m.g_at(m.lo_um + (i + 0.5) * step)));
        }
      for (int s = 0; s < S; ++s)
        for (int f = 0; f < F; ++f)
          for (int i = 0; i < M; ++i) {
            const double l = m.lo_um + (i + 0.5) * step;
            m.q.push_back(float(m.filters[f](l) * m.kappa_at(l) * stars[s].shape(l) * step));
          }
      break;
    }
    case SpectralMethod::Analytic: {
      if (F > kMaxAccumulators) throw Error("spectral: at most 64 filters");
      m.n_acc = F;
      set_analytic_breaks(m);
      for (int s = 0; s < S; ++s)
        for (int f = 0; f < F; ++f) {
          const Passband& curve = m.measured[size_t(f)];
          append_jumps(m, f, [&](double l) { return measured_response(curve, l) * stars[s].shape(l); }, m.jumps);
        }
      break;
    }
    case SpectralMethod::Preintegrated: {
      // The one element phi = 1: the star tables (build_star_tables) are then the whole
      // integral per star and filter over D, on the depths the basis methods tabulate.
      m.basis = GreedyBasis{};
      m.basis.phi.push_back(std::vector<double>(m.grid.lambda.size(), 1.0));
      m.settings.basis = 1;
      m.depth_step = float(m.max_depth / (settings.depth_nodes - 1));
      set_filters(m, filters);  // the star and emission tables
      return m;
    }
    case SpectralMethod::Projection:
    case SpectralMethod::LightBasis:
    case SpectralMethod::VoxelLight: {
      const bool light = settings.method == SpectralMethod::LightBasis;
      constexpr int kFamilyDepths = 128;
      const int family_temperatures = light ? 16 : 1;
      std::vector<std::vector<double>> family;
      const auto temperature_at = [](double u, int n) {
        return std::exp(std::log(kMinTemperature) + u * (std::log(kMaxTemperature) - std::log(kMinTemperature)) /
                                                        std::max(n - 1, 1));
      };
      for (int t = 0; t < family_temperatures; ++t)
        for (int d = 0; d < kFamilyDepths; ++d) {
          const double a = m.fit_depth * d / (kFamilyDepths - 1);
          const double T = temperature_at(t, family_temperatures);
          // Light-density members: the star's shape scaled to unit norm on the grid, so
          // that hot and cool stars weigh alike; attenuation keeps its absolute weight.
          std::vector<double> shape(m.grid.lambda.size(), 1.0);
          if (light) {
            for (size_t i = 0; i < shape.size(); ++i) shape[i] = planck_shape(m.grid.lambda[i], T);
            const double norm = m.grid.norm(shape);
            for (double& v : shape) v /= norm;
          }
          std::vector<double> f;
          for (size_t i = 0; i < m.grid.lambda.size(); ++i) f.push_back(shape[i] * std::exp(-m.kappa_grid[i] * a));
          if (settings.relative) {
            const double norm = m.grid.norm(f);
            for (double& v : f) v /= norm;
          }
          family.push_back(std::move(f));
        }
      m.basis = greedy_basis(m.grid, family, N, 0);
      for (int k : m.basis.chosen) {
        m.element_depth.push_back(m.fit_depth * (k % kFamilyDepths) / (kFamilyDepths - 1));
        if (light) m.element_temperature_K.push_back(temperature_at(k / kFamilyDepths, family_temperatures));
      }
      const int n = m.basis.size();  // may stop short when the family is exhausted
      m.settings.basis = n;
      m.n_temperature = light ? settings.temperature_nodes : 1;
      m.n_acc = light ? n : settings.method == SpectralMethod::VoxelLight ? F : S * n;
      if (m.n_acc > kMaxAccumulators && settings.method == SpectralMethod::VoxelLight)
        throw Error("spectral: at most 64 filters");
      if (m.n_acc > kMaxAccumulators)
        throw Error("spectral: " + std::to_string(S) + " stars x " + std::to_string(n) +
                    " basis elements exceed the 64 accumulators of a ray (use the light-density basis)");
      const int D = settings.depth_nodes;
      m.depth_step = float(m.max_depth / (D - 1));
      std::vector<double> f(m.grid.lambda.size());
      // A block per power p of kappa - kappa_c (tables, spectral_march.h): (kappa - kappa_c)^p s_T e^(-kappa D)
      // on the basis, its error relative to p = 0's function (the envelope: a centred power crosses zero).
      std::vector<double> envelope(m.grid.lambda.size());
      for (int p = 0; p < m.n_powers; ++p)
        for (int t = 0; t < m.n_temperature; ++t) {
          const double T = temperature_at(t, m.n_temperature);
          for (int d = 0; d < D; ++d) {
            for (size_t i = 0; i < f.size(); ++i) {
              envelope[i] =
                  (light ? planck_shape(m.grid.lambda[i], T) : 1.0) * std::exp(-m.kappa_grid[i] * d * m.depth_step);
              f[i] = envelope[i] * std::pow(m.kappa_grid[i] - m.kappa_center, p);
            }
            for (double c : settings.relative ? project_relative(m.grid, m.basis, f, envelope)
                                              : project(m.grid, m.basis, f))
              m.coeff.push_back(float(c));
          }
        }
      for (const SpectralStar& s : stars) {
        const double u = (std::log(s.temperature_K) - std::log(kMinTemperature)) /
                         (std::log(kMaxTemperature) - std::log(kMinTemperature)) * (m.n_temperature - 1);
        if (light && (u < 0 || u > m.n_temperature - 1))
          throw Error("spectral: star temperature " + to_text(s.temperature_K) +
                      " K is outside the light-density basis' range [2000, 60000] K");
        m.temperature_u.push_back(float(std::clamp(u, 0.0, double(m.n_temperature - 1))));
      }
      build_emission(m);  // before set_filters, which adds the emission's resolve columns
      set_filters(m, filters);
      return m;
    }
  }
  m.resolve.assign(size_t(F) * m.n_acc, 0.0f);
  for (int f = 0; f < F; ++f) m.resolve[size_t(f) * m.n_acc + f] = 1.0f;
  build_emission(m);
  add_emission_resolve(m);
  return m;
}

namespace {

// The emission's planes and tables (SpectralModel::emission_*): a line one
// plane, a continuum one per filter (Double, Analytic) or per basis element.
void build_emission(SpectralModel& m) {
  const SpectralMethod method = m.settings.method;
  const bool per_filter = method == SpectralMethod::Double || method == SpectralMethod::Analytic ||
                          method == SpectralMethod::Preintegrated;
  const int F = int(m.filters.size()), n = m.basis.size();
  m.emission_plane.clear();
  m.n_emission_planes = 0;
  for (const SpectralEmission& e : m.emission) {
    m.emission_plane.push_back(m.n_emission_planes);
    m.n_emission_planes += e.line_um > 0 ? 1 : per_filter ? F : n;
  }
  if (m.n_emission_planes > kMaxEmissionPlanes)
    throw Error("spectral.emission: " + std::to_string(m.n_emission_planes) + " numbers per ray (a line 1, a continuum " +
                (per_filter ? "1 per filter" : "1 per basis element") + "); at most " +
                std::to_string(kMaxEmissionPlanes));
  m.emission_q.clear();
  m.emission_jumps.clear();
  m.emission_coeff.clear();
  if (m.emission.empty()) return;
  if (method == SpectralMethod::Double) {
    const int M = m.settings.wavelengths;
    const double step = (m.hi_um - m.lo_um) / M;
    for (const SpectralEmission& e : m.emission)
      for (int f = 0; f < F; ++f)
        for (int i = 0; i < M; ++i) {
          const double l = m.lo_um + (i + 0.5) * step;
          m.emission_q.push_back(float(m.filters[f](l) * e.phi(l) * step));
        }
  } else if (method == SpectralMethod::Analytic) {
    // S_f phi as piecewise cubics on the shared breaks (a continuum's ends among them); a line: zeros.
    for (const SpectralEmission& e : m.emission)
      for (int f = 0; f < F; ++f) {
        const Passband& curve = m.measured[size_t(f)];
        append_jumps(
            m, f, [&](double l) { return e.line_um > 0 ? 0.0 : measured_response(curve, l) * e.phi(l); },
            m.emission_jumps);
      }
  } else if (method == SpectralMethod::Preintegrated) {
    // integral S_f phi e^(-kappa D) per component, depth and filter (zeros for a line).
    const int D = m.settings.depth_nodes;
    m.emission_coeff.assign(m.emission.size() * size_t(D) * F, 0.0f);
    std::vector<double> e(m.grid.lambda.size());
    for (int d = 0; d < D; ++d) {
      for (size_t i = 0; i < e.size(); ++i) e[i] = std::exp(-m.kappa_grid[i] * d * double(m.depth_step));
      for (size_t c = 0; c < m.emission.size(); ++c) {
        if (m.emission[c].line_um > 0) continue;
        for (int f = 0; f < F; ++f) {
          double sum = 0.0;
          for (size_t i = 0; i < e.size(); ++i) {
            const double l = m.grid.lambda[i];
            sum += m.grid.weight[i] * m.filters[f](l) * m.emission[c].phi(l) * e[i];
          }
          m.emission_coeff[(c * D + d) * F + f] = float(sum);
        }
      }
    }
  } else if (method == SpectralMethod::LightBasis) {
    // e^(-kappa D) on the basis (the other basis methods' first coefficient block is that table).
    std::vector<double> f(m.grid.lambda.size());
    for (int d = 0; d < m.settings.depth_nodes; ++d) {
      for (size_t i = 0; i < f.size(); ++i) f[i] = std::exp(-m.kappa_grid[i] * d * m.depth_step);
      for (double c : m.settings.relative ? project_relative(m.grid, m.basis, f) : project(m.grid, m.basis, f))
        m.emission_coeff.push_back(float(c));
    }
  }
}

// Widens the resolve (its n_acc star columns made) by the emission's planes: a
// line's column S_f(lambda_l); a continuum's, per filter (Double, Analytic) 1
// for its own filter, per basis element integral S_f phi b_j.
void add_emission_resolve(SpectralModel& m) {
  if (m.n_emission_planes == 0) return;
  const int F = int(m.filters.size()), A = m.n_acc, W = m.planes();
  const bool per_filter = m.settings.method == SpectralMethod::Double ||
                          m.settings.method == SpectralMethod::Analytic ||
                          m.settings.method == SpectralMethod::Preintegrated;
  std::vector<float> r(size_t(F) * W, 0.0f);
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < A; ++k) r[size_t(f) * W + k] = m.resolve[size_t(f) * A + k];
  for (size_t c = 0; c < m.emission.size(); ++c) {
    const SpectralEmission& e = m.emission[c];
    const int plane = A + m.emission_plane[c];
    for (int f = 0; f < F; ++f) {
      float* row = &r[size_t(f) * W];
      if (e.line_um > 0) {
        row[plane] = float(m.filters[f](e.line_um));
      } else if (per_filter) {
        row[plane + f] = 1.0f;
      } else {
        for (int j = 0; j < m.basis.size(); ++j) {
          double sum = 0.0;
          for (size_t i = 0; i < m.grid.lambda.size(); ++i) {
            const double l = m.grid.lambda[i];
            sum += m.grid.weight[i] * m.filters[f](l) * e.phi(l) * m.basis.phi[j][i];
          }
          row[plane + j] = float(sum);
        }
      }
    }
  }
  m.resolve = std::move(r);
}

// VoxelLight: Q_fj(star, D) = integral S_f kappa s e^(-kappa D) phi_j on the
// inner products' grid, at the coefficient table's depths; the resolve is the
// identity (one accumulator per filter).
void build_star_tables(SpectralModel& m) {
  const int F = int(m.filters.size()), n = m.basis.size(), S = int(m.stars.size()), D = m.settings.depth_nodes;
  if (F > kMaxAccumulators) throw Error("spectral: at most 64 filters");
  const size_t G = m.grid.lambda.size();
  // h[(s F + f) n + j][i] = weight S_f kappa s phi_j at node i: Q is then h . e^(-kappa D).
  std::vector<std::vector<double>> h(size_t(S) * F * n, std::vector<double>(G));
  for (int s = 0; s < S; ++s)
    for (int f = 0; f < F; ++f)
      for (size_t i = 0; i < G; ++i) {
        const double l = m.grid.lambda[i];
        const double base = m.grid.weight[i] * m.filters[f](l) * m.kappa_grid[i] * m.stars[s].shape(l);
        for (int j = 0; j < n; ++j) h[(size_t(s) * F + f) * n + j][i] = base * m.basis.phi[j][i];
      }
  m.n_acc = F;
  const int P = m.n_powers;  // tables: a block per power, Q^p = integral S_f kappa (kappa - kappa_c)^p s e^(-kappa D) phi_j
  m.star_coeff.assign(size_t(S) * P * D * F * n, 0.0f);
  std::vector<double> e(G);
  for (int p = 0; p < P; ++p)
    for (int d = 0; d < D; ++d) {
      for (size_t i = 0; i < G; ++i)
        e[i] = std::pow(m.kappa_grid[i] - m.kappa_center, p) * std::exp(-m.kappa_grid[i] * d * double(m.depth_step));
      for (int s = 0; s < S; ++s)
        for (int fj = 0; fj < F * n; ++fj) {
          const std::vector<double>& row = h[size_t(s) * F * n + fj];
          double sum = 0.0;
          for (size_t i = 0; i < G; ++i) sum += row[i] * e[i];
          m.star_coeff[((size_t(s) * P + p) * D + d) * F * n + fj] = float(sum);
        }
    }
  m.resolve.assign(size_t(F) * F, 0.0f);
  for (int f = 0; f < F; ++f) m.resolve[size_t(f) * F + f] = 1.0f;
}

}  // namespace

void set_filters(SpectralModel& m, const std::vector<std::pair<std::string, Passband>>& filters) {
  const bool light = m.settings.method == SpectralMethod::LightBasis;
  const bool voxel = m.settings.method == SpectralMethod::VoxelLight;
  const bool pre = m.settings.method == SpectralMethod::Preintegrated;
  if (!light && !voxel && !pre && m.settings.method != SpectralMethod::Projection)
    throw Error("spectral: filters change on a basis or tables only (the projection, light-density, voxel-light or "
                "pre-integrated method)");
  m.filter_names.clear();
  m.filters.clear();
  m.fits.clear();
  m.measured.clear();
  for (const auto& [name, band] : filters) {
    const double lo = band.wavelength_nm.front() / 1000.0, hi = band.wavelength_nm.back() / 1000.0;
    if (lo < m.lo_um - 1e-12 || hi > m.hi_um + 1e-12)
      throw Error("spectral: filter '" + name + "' spans [" + to_text(lo) + ", " + to_text(hi) +
                  "] um, outside the basis' range [" + to_text(m.lo_um) + ", " + to_text(m.hi_um) + "] um");
    FitReport r;
    m.filter_names.push_back(name);
    m.filters.push_back(fit_passband(band, 2e-3, &r));
    m.fits.push_back(r);
    m.measured.push_back(band);
  }
  if (voxel || pre) {
    if (pre) build_emission(m);  // its continua's tables hold the filters
    build_star_tables(m);
    add_emission_resolve(m);
    return;
  }
  const int F = int(filters.size()), n = m.basis.size(), S = int(m.stars.size());
  const size_t G = m.grid.lambda.size();
  m.resolve.assign(size_t(F) * m.n_acc, 0.0f);
  for (int fi = 0; fi < F; ++fi)
    for (int s = 0; s < (light ? 1 : S); ++s)
      for (int j = 0; j < n; ++j) {
        double sum = 0.0;
        for (size_t i = 0; i < G; ++i) {
          const double l = m.grid.lambda[i];
          sum += m.grid.weight[i] * m.filters[fi](l) * m.kappa_grid[i] * (light ? 1.0 : m.stars[s].shape(l)) *
                 m.basis.phi[j][i];
        }
        m.resolve[size_t(fi) * m.n_acc + s * n + j] = float(sum);
      }
  add_emission_resolve(m);
}

SpectralSceneView view_of(const SpectralModel& m) {
  SpectralSceneView v;
  v.method = m.settings.method;
  v.n_acc = m.n_acc;
  v.max_eye_depth = m.max_eye_depth;
  v.n_lambda = int(m.kappa.size());
  v.kappa = m.kappa.data();
  v.q = m.q.data();
  v.C_T = m.C_T;
  v.breaks = m.breaks.data();
  v.jumps = m.jumps.data();
  v.break_range = m.break_range.data();
  v.n_breaks = int(m.breaks.size());
  if (!m.break_range.empty()) {
    v.break_lo = v.n_breaks;
    v.break_hi = -1;
    for (size_t f = 0; f + 1 < m.break_range.size(); f += 2) {
      v.break_lo = std::min(v.break_lo, m.break_range[f]);
      v.break_hi = std::max(v.break_hi, m.break_range[f + 1]);
    }
  }
  v.n_basis = m.basis.size();
  v.n_depth = m.settings.depth_nodes;
  v.n_temperature = m.n_temperature;
  v.depth_step = m.depth_step;
  v.inv_depth_step = 1.0f / m.depth_step;
  v.coeff = m.coeff.data();
  v.star_coeff = m.star_coeff.data();
  v.n_powers = m.n_powers;
  v.kappa_center = float(m.kappa_center);
  v.varying = m.varying();
  for (size_t i = 0; i < m.node_albedo.size(); ++i) {
    v.node_albedo[i] = float(m.node_albedo[i]);
    v.node_g[i] = float(m.node_g[i]);
  }
  v.lambda_albedo = m.lambda_albedo.empty() ? nullptr : m.lambda_albedo.data();
  v.lambda_g = m.lambda_g.empty() ? nullptr : m.lambda_g.data();
  for (size_t i = 0; i < m.node_kappa.size(); ++i) v.node_kappa[i] = float(m.node_kappa[i]);
  const int K = int(m.node_kappa.size());
  for (int p = 0; p < K; ++p)
    for (int k = 0; k < K; ++k) {
      v.node_to_power[p * kMaxTableNodes + k] = float(m.node_to_power[size_t(p) * K + k]);
      v.node_weight[p * kMaxTableNodes + k] = float(m.node_to_power[size_t(p) * K + k] / m.node_kappa[size_t(k)]);
    }
  // Emission: the spectra's tables; each component's weight is the renderer's.
  v.n_emission = int(m.emission.size());
  v.n_emission_planes = m.n_emission_planes;
  for (int c = 0; c < v.n_emission; ++c) {
    SpectralEmissionView& e = v.emission[c];
    e.plane = m.emission_plane[size_t(c)];
    e.line = m.emission[size_t(c)].line_um > 0;
    e.line_kappa = e.line ? float(m.kappa_at(m.emission[size_t(c)].line_um)) : 0.0f;
  }
  v.emission_q = m.emission_q.data();
  v.emission_jumps = m.emission_jumps.data();
  v.emission_coeff = m.emission_coeff.empty() ? m.coeff.data() : m.emission_coeff.data();
  return v;  // n_nodes stays 0 (the thin limit) until the renderer is given a table
}

double emission_reference(const SpectralModel& m, int filter, int component, double D) {
  const PiecewisePolynomial& S = m.filters[size_t(filter)];
  const SpectralEmission& e = m.emission[size_t(component)];
  if (e.line_um > 0) return S(e.line_um) * std::exp(-m.kappa_at(e.line_um) * D);
  const double lo = std::max(S.breaks.front(), e.lo_um), hi = std::min(S.breaks.back(), e.hi_um);
  double sum = 0.0;
  for (int seg = 0; seg < S.segments(); ++seg) {
    const double a = std::max(S.breaks[seg], lo), b = std::min(S.breaks[seg + 1], hi);
    for (int k = 0; a < b && k < 8; ++k)
      sum += gauss5([&](double l) { return S(l) * e.phi(l) * std::exp(-m.kappa_at(l) * D); }, a + (b - a) * k / 8,
                    a + (b - a) * (k + 1) / 8);
  }
  return sum;
}

double reference_integral(const SpectralModel& m, int filter, const SpectralStar& star, double D) {
  const PiecewisePolynomial& S = m.filters[size_t(filter)];
  double sum = 0.0;
  for (int seg = 0; seg < S.segments(); ++seg) {
    const double a = S.breaks[seg], b = S.breaks[seg + 1];
    for (int k = 0; k < 8; ++k) {
      const double lo = a + (b - a) * k / 8, hi = a + (b - a) * (k + 1) / 8;
      sum += gauss5(
          [&](double l) {
            const double kappa = m.kappa_at(l);
            return S(l) * kappa * star.shape(l) * std::exp(-kappa * D);
          },
          lo, hi);
    }
  }
  return sum;
}

}  // namespace nebula::spectral
