// `nebula slab`: diffuse reflectance and total transmittance of a
// plane-parallel slab, the tabulator's transport checked against exact results.
#include <cstdio>
#include <memory>
#include <string>

#include "app/cli_support.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/progress.h"
#include "montecarlo/slab.h"

namespace nebula::app {

void add_slab_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "slab", "diffuse reflectance and total transmittance of a plane-parallel slab (index 1)");
  struct Options {
    SlabParams p;
    std::string photons = "1e6", backend = "auto";
    bool json = false, analog = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--albedo", o->p.albedo, "single-scattering albedo")->required();
  cmd->add_option("--g", o->p.g, "HG asymmetry")->required();
  cmd->add_option("--tau", o->p.tau, "optical thickness (extinction)")->required();
  cmd->add_option("--incidence-deg", o->p.incidence_deg, "beam angle from the normal")->capture_default_str();
  cmd->add_option("--photons", o->photons, "photons")->capture_default_str();
  cmd->add_option("--seed", o->p.seed, "Philox key")->capture_default_str();
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_flag("--analog", o->analog, "no forced first scattering");
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o] {
    SlabParams p = o->p;
    p.photons = parse_count("--photons", o->photons, 2, double(uint64_t(1) << 30));
    p.forced_first_scattering = !o->analog;
    naming_options({{"albedo", "--albedo"}, {"g", "--g"}, {"tau", "--tau"}, {"incidence_deg", "--incidence-deg"},
                    {"photons", "--photons"}},
                   [&] { validate(p); });
    const Backend backend = parse_backend(o->backend);
    std::unique_ptr<Progress> progress;
    if (!o->json) progress = std::make_unique<Progress>("slab", p.photons);
    const SlabResult r = simulate_slab(p, backend, progress.get());
    if (progress) progress->finish();
    if (o->json) {
      std::printf(
          "{\"R_diffuse\": %.9g, \"R_stderr\": %.9g, \"T_total\": %.9g, \"T_stderr\": %.9g, "
          "\"T_unscattered\": %.9g, \"photons\": %llu, \"scattering_events\": %llu, "
          "\"capped_photons\": %llu, \"seconds\": %.6g, \"backend\": \"%s\"}\n",
          r.R_diffuse, r.R_stderr, r.T_total, r.T_stderr, r.T_unscattered,
          (unsigned long long)p.photons, (unsigned long long)r.scattering_events,
          (unsigned long long)r.capped_photons, r.seconds, to_string(backend));
      return;
    }
    std::printf("slab: a = %g, g = %g, tau = %g, incidence %g deg, %llu photons\n", p.albedo, p.g,
                p.tau, p.incidence_deg, (unsigned long long)p.photons);
    std::printf("diffuse reflectance   R = %.6f +- %.6f\n", r.R_diffuse, r.R_stderr);
    std::printf("total transmittance   T = %.6f +- %.6f (unscattered %.6f, exact)\n", r.T_total,
                r.T_stderr, r.T_unscattered);
    std::printf("%.3g scattering events, %llu capped, %.3f s on %s\n", double(r.scattering_events),
                (unsigned long long)r.capped_photons, r.seconds, r.device.c_str());
  });
}

}  // namespace nebula::app
