#pragma once
// Everything the spectral marcher reads besides the grid and the bakes, built
// on the host from the filters, the stars' spectra and the dust law: the
// wavelength samples of the double integral, the filter x star polynomials of
// the analytic integral, the greedy bases and their coefficient tables, and
// the resolve matrix that turns a ray's accumulators into one value per filter.
#include <string>
#include <vector>

#include "illumination/extinction.h"
#include "illumination/passband.h"
#include "spectral/basis.h"
#include "spectral/piecewise_polynomial.h"
#include "spectral/spectra.h"
#include "spectral/spectral_march.h"

namespace nebula::spectral {

// kappa(lambda) = tau(lambda) / tau_V: the report's C_T / lambda, or the
// scene's CCM89 / O'Donnell law; both normalised so that their average over
// the V filter is 1 (tau_V is the V-band depth, DESIGN.md section 3).
enum class Attenuation { Inverse, Law };

// The default family range: V-band optical paths up to 8 (transmission 3e-4).
constexpr double kFitDepth = 8.0;

struct SpectralSettings {
  SpectralMethod method = SpectralMethod::Projection;
  int basis = 4;            // elements of the greedy basis (Projection, LightBasis, VoxelLight), 1..16
  int wavelengths = 20;     // samples of the double integral over the filters' span
  Attenuation attenuation = Attenuation::Inverse;
  double R_V = 5.0;
  ExtinctionLaw law = ExtinctionLaw::CCM89;
  // The coefficient table's optical paths D in [0, max_depth] (V band); a pair
  // past it is dropped. 0: where the longest wavelength is attenuated to the
  // marcher's cut, e^(-kappa_min D) = 1e-4.
  double max_depth = 0;
  // The basis family's optical paths a in [0, fit_depth] (V band), where the
  // basis is chosen to be accurate; past it the error grows (bounded by the
  // relative projection). 0: the default kFitDepth.
  double fit_depth = 0;
  // The error measure of the greedy and the coefficients. Relative (ours): each
  // member scaled to unit norm for the greedy, coefficients of least relative
  // error (project_relative). Absolute (the report's): members as they are,
  // orthogonal projection; its error is absolute, so light that arrives through
  // long optical paths (dim, but all a pixel behind dense dust receives) is
  // poorly represented (docs/spectral.md).
  bool relative = true;
  int depth_nodes = 2048;       // coefficient table over a
  int temperature_nodes = 48;   // LightBasis: table over log T in [2000, 60000] K
  int grid_nodes = 1024;        // wavelength grid of the inner products
  // The basis' wavelength range (um); 0: the filters' span. A range fixed
  // ahead lets set_filters change filters with the same basis and tables.
  double lo_um = 0, hi_um = 0;
  // VoxelLight: a voxel whose centre lies within this many voxels of a star takes
  // that star's pair exactly in the march (1/r^2 is not smooth there; docs/spectral.md).
  double near_voxels = 10;
  // Tables (docs/spectral.md, "Tables"): the attenuations kappa at which a pair
  // reads the voxel's scattering table P(a tau_V kappa, mu), 1..kMaxTableNodes
  // (1: at kappa = 1, the V band's depth, for every wavelength; n >= 2: evenly
  // over the basis' range, P / kappa a polynomial of degree n - 1 in kappa
  // between them); 0: the thin-voxel limit only. The renderer uses a table only
  // when given one.
  int table_nodes = 0;
  // Albedo and g varying with wavelength (docs/spectral.md, "Albedo and g with
  // wavelength"): their values at curve_um (increasing; both curves as long),
  // linear between and constant beyond; empty: the renderer's one albedo and g. With a curve every
  // table node scatters with its own (a, g), through its own table when the
  // renderer has tables (SpectralRenderInputs::node_tables), else the thin-voxel
  // limit at that node; so table_nodes >= 1, and the double integral, which
  // would need a table per wavelength, takes them in the thin limit only.
  std::vector<double> curve_um, curve_albedo, curve_g;
};

struct SpectralStar {
  double temperature_K = 5772;
  const TabulatedSpectrum* table = nullptr;  // overrides the black body (not with LightBasis)
  bool wien = false;                         // Wien's approximation instead of Planck
  double shape(double lambda_um) const;
};

// An emission component's spectrum (docs/spectral.md, "Emission"): the voxel
// adds w(x) phi(lambda) to a ray crossing it along one voxel edge, w from the
// renderer's inputs. A line: phi = delta(lambda - line_um), so w is the line's
// radiance (L_sun pc^-2 sr^-1). A continuum: phi = sum_k c_k lambda^k (lambda
// in um) on [lo_um, hi_um] (0, 0: the basis' range), zero outside; w phi in
// L_sun pc^-2 sr^-1 um^-1.
struct SpectralEmission {
  double line_um = 0;              // > 0: a line
  std::vector<double> continuum;   // else: c_0, c_1, ...
  double lo_um = 0, hi_um = 0;
  double phi(double lambda_um) const;  // a continuum's spectrum (0 outside its range)
};

struct SpectralModel {
  SpectralSettings settings;
  std::vector<std::string> filter_names;
  std::vector<PiecewisePolynomial> filters;  // fitted S_f
  std::vector<Passband> measured;            // the curves as given (Analytic: exact, linear between rows)
  std::vector<FitReport> fits;
  double lo_um = 0, hi_um = 0;  // the filters' span
  double C_T = 0;               // kappa = C_T / lambda (Inverse)
  WavelengthGrid grid;
  std::vector<double> kappa_grid;  // kappa on the grid
  GreedyBasis basis;
  // The chosen members: their optical path a (V band) and, for the
  // light-density basis, their star temperature (K).
  std::vector<double> element_depth, element_temperature_K;
  double max_depth = 0, fit_depth = 0;
  int n_stars = 0;
  std::vector<SpectralStar> stars;
  // Arrays of the view (host copies).
  int n_acc = 0;
  std::vector<float> kappa, q, coeff, temperature_u;
  std::vector<float> star_coeff;  // VoxelLight: [star][depth][filter][basis] (spectral_march.h)
  // Analytic (Algorithm 1; SpectralSceneView): the breaks shared by every
  // filter, star and continuum, the jumps of each piecewise cubic at them, and
  // each filter's first and last break.
  std::vector<double> breaks, jumps;
  std::vector<int> break_range;
  float depth_step = 1;
  int n_temperature = 1;
  float max_eye_depth = 1e30f;
  std::vector<float> resolve;  // [filter][acc]
  // Tables: the nodes' attenuations and the map from P / kappa at them to the
  // coefficients of the powers of kappa - kappa_center ([p][m]), the middle of
  // the nodes' range (centred powers: small beside the constant term, so a sum
  // over them does not cancel); n_powers blocks in coeff and star_coeff.
  std::vector<double> node_kappa, node_to_power;
  double kappa_center = 0;
  // With the curves: each node's wavelength, albedo and g; the double integral's
  // albedo and g at each of its wavelengths.
  std::vector<double> node_lambda, node_albedo, node_g;
  std::vector<float> lambda_albedo, lambda_g;
  bool varying() const { return !settings.curve_um.empty(); }
  // The curves at lambda (um).
  double albedo_at(double lambda_um) const;
  double g_at(double lambda_um) const;
  int n_powers = 1;
  // Emission: its planes follow the n_acc star planes (the resolve's columns
  // n_acc .. n_acc + n_emission_planes - 1; spectral_march.h, add_emission).
  std::vector<SpectralEmission> emission;  // lo_um, hi_um resolved
  int n_emission_planes = 0;
  std::vector<int> emission_plane;     // per component: its first plane (after the star planes)
  std::vector<float> emission_q;       // Double: [component][filter][lambda] S_f phi dlambda
  std::vector<double> emission_jumps;  // Analytic: S_f phi's jumps, [component][filter][break][degree + 1]
  std::vector<float> emission_coeff;   // LightBasis: e^(-kappa D) on the basis, [d][j] (else coeff's first block)
  int planes() const { return n_acc + n_emission_planes; }
  double kappa_at(double lambda_um) const;
  // A wavelength (um) in the basis' range where kappa(lambda) = kappa (the
  // closest on the inner products' grid, refined between its neighbours).
  double wavelength_of_kappa(double kappa) const;
};

// Errors (ParameterError-free: callers name their keys): no filter, a filter
// outside the law's range, basis < 1 or > 16, wavelengths < 2, a temperature
// not positive, Analytic with the Law attenuation, LightBasis with a
// tabulated star, VoxelLight with more than 32 stars or near_voxels < 0,
// table_nodes outside 0..4.
// Emission errors name "spectral.emission.<i>": a line outside the basis'
// range, a continuum range outside it or negative somewhere on its range,
// more than kMaxEmissionPlanes planes per ray.
SpectralModel build_spectral_model(const std::vector<std::pair<std::string, Passband>>& filters,
                                   const std::vector<SpectralStar>& stars, const SpectralSettings& settings,
                                   const std::vector<SpectralEmission>& emission = {});

// New filters on the same basis and tables (Projection, LightBasis): only the
// resolve matrix changes, no march or bake (Barrès' filters changed at run
// time). VoxelLight: the per-star filter tables are rebuilt (the filters enter
// its pre-pass, so the march re-runs; no bake). Refuses a filter outside the
// basis' wavelength range.
void set_filters(SpectralModel& m, const std::vector<std::pair<std::string, Passband>>& filters);

// The view of a model (pointers into it; stars and grid filled by the renderer).
SpectralSceneView view_of(const SpectralModel& m);

// The exact integral of S_f kappa s e^(-kappa D) over lambda for one filter
// and star (adaptive Gauss-Legendre on the fitted S_f): the reference the
// methods are measured against.
double reference_integral(const SpectralModel& m, int filter, const SpectralStar& star, double D);
// The same for emission component c seen through V-band depth D: integral
// S_f phi e^(-kappa D) dlambda (a line: S_f(lambda_l) e^(-kappa_l D)).
double emission_reference(const SpectralModel& m, int filter, int component, double D);

}  // namespace nebula::spectral
