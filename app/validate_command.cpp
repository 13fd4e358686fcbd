// `nebula validate montecarlo`: the tabulator's transport against analytic
// answers (validation/montecarlo_validation.h), as a pass/fail table.
#include <cstdio>
#include <memory>
#include <string>

#include "app/cli_support.h"
#include "app/commands.h"
#include "core/error.h"
#include "validation/montecarlo_validation.h"

namespace nebula::app {

void add_validate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("validate", "check the physics against exact results");
  cmd->require_subcommand(1);
  auto* mc = cmd->add_subcommand("montecarlo", "the tabulator's transport against analytic answers");
  auto backend = std::make_shared<std::string>("auto");
  auto effort = std::make_shared<double>(1.0);
  mc->add_option("--backend", *backend, "cpu, cuda or auto")->capture_default_str();
  mc->add_option("--effort", *effort, "scale of the photon counts (tolerances follow)")
      ->capture_default_str();
  mc->callback([backend, effort] {
    if (!(*effort > 0 && *effort <= 1000)) throw Error("--effort: must be in (0, 1000]");
    const Backend b = parse_backend(*backend);
    std::printf("validating the Monte-Carlo transport on %s\n\n", to_string(b));
    const std::vector<ValidationRow> rows = validate_montecarlo(b, *effort);
    std::printf("%-70s %11s %11s %10s  %s\n", "check", "expected", "measured", "tolerance", "result");
    int failed = 0;
    for (const ValidationRow& r : rows) {
      std::printf("%-70s %11.6g %11.6g %10.3g  %s  (%s)\n", r.check.c_str(), r.expected, r.measured,
                  r.tolerance, r.pass ? "pass" : "FAIL", r.basis.c_str());
      failed += !r.pass;
    }
    std::printf("\nangular binning with 72 bins: the thin-limit table against p_HG (lookup as the "
                "renderer does), and MC noise at 1e6 photons per row\n");
    std::printf("%6s %-14s %12s %12s %14s %12s %12s\n", "g", "binning", "interp rms", "interp max",
                "forward error", "noise rms", "combined");
    for (const BinningRow& r : compare_binnings({0.0, 0.6, 0.9, 0.95}, 72, 1e6))
      std::printf("%6.2f %-14s %11.3f%% %11.2f%% %13.2f%% %11.3f%% %11.3f%%\n", r.g,
                  to_string(r.binning), 100 * r.interp_rms, 100 * r.interp_max,
                  100 * r.forward_error, 100 * r.noise_rms, 100 * r.combined_rms);
    std::printf("\n%zu passed, %d failed\n", rows.size() - failed, failed);
    if (failed) throw Error(std::to_string(failed) + " validation check(s) failed");
  });
}

}  // namespace nebula::app
