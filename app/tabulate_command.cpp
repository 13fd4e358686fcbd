// `nebula tabulate` and `nebula table info`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "app/cli_support.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/math.h"
#include "core/progress.h"
#include "montecarlo/table_conversion.h"
#include "montecarlo/tabulate.h"
#include "tables/scattering_table.h"
#include "tables/table_file.h"

namespace nebula::app {
namespace {

// The entry with the largest relative standard error among entries holding
// at least 1% of their row's peak (the rest are dominated by empty bins).
void print_error_summary(const ScatteringTable& t) {
  double worst_abs = 0, worst_rel = 0;
  int wi = 0, wk = 0;
  for (int i = 1; i < t.n_tau(); ++i) {
    float peak = 0;
    for (int k = 0; k < t.n_mu(); ++k) peak = std::max(peak, t.P[t.index(i, k)]);
    for (int k = 0; k < t.n_mu(); ++k) {
      const double v = t.P[t.index(i, k)], se = t.P_stderr[t.index(i, k)];
      worst_abs = std::max(worst_abs, se);
      if (v > 0.01 * peak && se / v > worst_rel) {
        worst_rel = se / v;
        wi = i;
        wk = k;
      }
    }
  }
  std::printf("largest standard error: %.3g absolute; %.2f%% relative (tau = %.3g, theta = %.1f deg)\n",
              worst_abs, 100 * worst_rel, t.tau[wi], std::acos(t.mu[wk]) * 180 / kPiD);
}

void print_totals(const ScatteringTable& t, int rows) {
  std::printf("%10s %14s %12s %14s\n", "tau_sct", "scattered", "+-", "unscattered");
  const int n = t.n_tau();
  int last = -1;
  for (int r = 0; r < rows; ++r) {
    const int i = static_cast<int>(std::lround(double(r) * (n - 1) / (rows - 1)));
    if (i == last) continue;
    last = i;
    std::printf("%10.4g %14.6f %12.2g %14.6f\n", t.tau[i], t.total[i], t.total_stderr[i],
                t.unscattered[i]);
  }
}

void run_tabulate(const TabulateParams& p, const std::string& backend_name, const std::string& out,
                  bool force, bool quiet) {
  validate(p);
  check_output_path("-o", out, force);
  const Backend backend = parse_backend(backend_name);
  std::unique_ptr<Progress> progress;
  if (!quiet)
    progress = std::make_unique<Progress>("tabulate", photons_of_table(p));
  const Tabulation tab = tabulate(p, backend, progress.get());
  if (progress) progress->finish();
  const ScatteringTable table = to_table(tab);
  write_table(table, out, force);

  const double photons = double(photons_of_table(p));
  std::printf("P(tau, mu) table: %d tau_sct x %d %s bins, tau_sct in [0, %g], albedo %g, g %g, %s beam\n",
              p.tau_bins, p.mu_bins, to_string(p.binning), p.tau_max, p.albedo, p.g,
              to_string(p.beam));
  std::printf("photons: %.3g (%.3g per row, rows of tau_sct < 1 up to %d times more), scattering events %.3g, "
              "capped by the order limit %llu\n",
              photons, double(p.photons_per_row), p.thin_boost, double(tab.scattering_events),
              static_cast<unsigned long long>(tab.capped_photons));
  std::printf("time: %.3f s on %s: %.3g photons/s, %.3g events/s\n", tab.seconds,
              tab.device.c_str(), photons / tab.seconds, tab.scattering_events / tab.seconds);
  print_error_summary(table);
  print_totals(table, 6);
  std::printf("wrote %s\n", out.c_str());
}

}  // namespace

void add_tabulate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "tabulate",
      "Monte-Carlo table P(tau_sct, theta) of light scattered by one voxel (HG phase function) to HDF5");
  struct Options {
    TabulateParams p;
    std::string photons = "1e5", binning = "uniform-mu", illumination = "parallel", backend = "auto";
    std::string out;
    bool force = false, quiet = false, analog = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--albedo", o->p.albedo, "single-scattering albedo a in [0, 1]")->capture_default_str();
  cmd->add_option("--g", o->p.g, "HG asymmetry g, |g| < 1")->capture_default_str();
  cmd->add_option("--tau-max", o->p.tau_max, "largest scattering depth per voxel edge")->capture_default_str();
  cmd->add_option("--tau-bins", o->p.tau_bins, "rows: tau_sct values from 0 to tau-max")->capture_default_str();
  cmd->add_option("--mu-bins", o->p.mu_bins, "scattering-angle bins")->capture_default_str();
  cmd->add_option("--binning", o->binning, "uniform-mu (the paper's) or uniform-theta (resolves forward peaks)")
      ->capture_default_str();
  cmd->add_option("--photons", o->photons, "photons per row (1e3 ... 2^30)")->capture_default_str();
  cmd->add_option("--thin-boost", o->p.thin_boost,
                  "rows of tau_sct < 1 trace photons x min(this, floor(1 / tau_sct)) (1: the same in every row)")
      ->capture_default_str();
  cmd->add_option("--seed", o->p.seed, "Philox key: same seed, same table")->capture_default_str();
  cmd->add_option("--illumination", o->illumination,
                  "parallel (beam over the cross-section) or pencil (the paper's ray through the centre)")
      ->capture_default_str();
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_flag("--analog", o->analog, "no forced first scattering (for checking the variance reduction)");
  cmd->add_option("-o,--output", o->out, "output HDF5 file")->required();
  cmd->add_flag("--force", o->force, "overwrite an existing output file");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress bar");
  cmd->callback([o] {
    TabulateParams p = o->p;
    p.photons_per_row = parse_count("--photons", o->photons, 2, double(kMaxPhotonsPerRow));
    if (!parse_angular_binning(o->binning, p.binning))
      throw Error("--binning: expected uniform-mu or uniform-theta, got '" + o->binning + "'");
    if (o->illumination == "parallel") p.beam = Beam::Parallel;
    else if (o->illumination == "pencil") p.beam = Beam::Pencil;
    else throw Error("--illumination: expected parallel or pencil, got '" + o->illumination + "'");
    p.forced_first_scattering = !o->analog;
    naming_options({{"albedo", "--albedo"}, {"g", "--g"}, {"tau_max", "--tau-max"}, {"tau_bins", "--tau-bins"},
                    {"mu_bins", "--mu-bins"}, {"photons_per_row", "--photons"}, {"thin_boost", "--thin-boost"},
                    {"backend", "--backend"}},
                   [&] { run_tabulate(p, o->backend, o->out, o->force, o->quiet); });
  });
}

void add_table_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("table", "inspect scattering tables");
  cmd->require_subcommand(1);
  auto* info = cmd->add_subcommand("info", "attributes, axes and the scattered fraction against tau");
  auto file = std::make_shared<std::string>();
  auto rows = std::make_shared<int>(11);
  info->add_option("FILE", *file, "table written by `nebula tabulate`")->required();
  info->add_option("--rows", *rows, "how many tau rows of the totals to list")->capture_default_str();
  info->callback([file, rows] {
    const ScatteringTable t = read_table(*file);
    std::printf("%s: schema %d, written by %s\n", file->c_str(), t.schema_version, t.generator.c_str());
    std::printf("dust: albedo %g, g %g, phase %s; voxel %s, %s beam\n", t.albedo, t.g,
                t.phase.c_str(), t.geometry.c_str(), t.illumination.c_str());
    std::printf("axes: %d tau_sct in [0, %g]; %d %s bins of cos(theta)\n", t.n_tau(), t.tau_max(),
                t.n_mu(), to_string(t.mu_binning));
    std::printf("Monte Carlo: %llu photons per row (rows of tau_sct < 1: up to %llu times more), seed %llu, %s, "
                "forced first scattering %s,\n"
                "  roulette below %g (survival %g), order cap %d (%llu photons capped), %.3g events\n",
                (unsigned long long)t.photons_per_row, (unsigned long long)t.thin_boost, (unsigned long long)t.seed,
                t.rng.c_str(),
                t.forced_first_scattering ? "on" : "off", t.roulette_threshold, t.roulette_survival,
                t.max_orders, (unsigned long long)t.capped_photons, double(t.scattering_events));
    print_error_summary(t);
    print_totals(t, std::max(2, *rows));
  });
}

}  // namespace nebula::app
