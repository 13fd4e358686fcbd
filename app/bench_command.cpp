// `nebula slab`, `nebula validate montecarlo` and `nebula bench tabulate`.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "app/commands.h"
#include "app/output_path.h"
#include "raycast/axial_renderer.h"
#include "core/error.h"
#include "core/progress.h"
#include "montecarlo/slab.h"
#include "validation/montecarlo_validation.h"
#include "raycast/axial_map.h"
#include "validation/benchmarks.h"

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
    validate(p);
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

void add_bench_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("bench", "measure speed (medians after a warm-up)");
  cmd->require_subcommand(1);
  auto* tab = cmd->add_subcommand("tabulate", "photons and scattering events per second, CPU and CUDA; "
                                              "table error against photons per row");
  struct Options {
    std::string backends = "auto";
    int repeats = 5;
    int tau_bins = 1000;
    std::string photons = "1e6";
    bool convergence = true;
  };
  auto o = std::make_shared<Options>();
  tab->add_option("--backend", o->backends, "cpu, cuda, both or auto (= both when a GPU is present)")
      ->capture_default_str();
  tab->add_option("--repeats", o->repeats, "timed runs after the warm-up")->capture_default_str();
  tab->add_option("--tau-bins", o->tau_bins, "rows of the GPU table")->capture_default_str();
  tab->add_option("--photons", o->photons, "photons per row of the GPU table")->capture_default_str();
  tab->add_flag("!--no-convergence", o->convergence, "skip the error-against-photons study");
  tab->callback([o] {
    if (o->repeats < 1) throw Error("--repeats: must be at least 1");
    std::vector<Backend> backends;
    if (o->backends == "both" || (o->backends == "auto" && gpu_available()))
      backends = {Backend::Cpu, Backend::Cuda};
    else
      backends = {parse_backend(o->backends)};
    const uint64_t gpu_photons = parse_count("--photons", o->photons, 2, double(kMaxPhotonsPerRow));
    std::printf("| backend | device | table | photons/row | transport s (median of %d) | end-to-end s | "
                "photons/s | events/s | events/photon |\n|---|---|---|---|---|---|---|---|---|\n",
                o->repeats);
    for (Backend b : backends) {
      TabulateParams p;
      p.tau_bins = o->tau_bins;
      // The CPU measures a 1/100 slice of the work; rates are per photon and event.
      p.photons_per_row = b == Backend::Cuda ? gpu_photons : std::max<uint64_t>(1000, gpu_photons / 100);
      const ThroughputResult r = bench_throughput(b, p, o->repeats);
      std::printf("| %s | %s | %d x %d | %.3g | %.4f | %.4f | %.3g | %.3g | %.2f |\n", r.backend.c_str(),
                  r.device.c_str(), p.tau_bins, p.mu_bins, double(p.photons_per_row), r.median_seconds,
                  r.median_wall, r.photons_per_second, r.events_per_second, r.events_per_photon);
      std::fflush(stdout);
    }
    if (!o->convergence) return;
    for (Backend b : backends) {
      TabulateParams p;
      std::vector<uint64_t> counts{1000, 10000, 100000, 1000000};
      if (b == Backend::Cpu) {
        p.tau_bins = 50;  // the CPU studies a 50-row table to stay within minutes
        counts = {1000, 10000, 100000};
      }
      std::printf("\nerror against an independent 16x reference, %s, %d x %d table (a = %g, g = %g)\n",
                  to_string(b), p.tau_bins, p.mu_bins, p.albedo, p.g);
      std::printf("| photons/row | transport s | rel. L2 error | predicted from stderr | RMS z |\n"
                  "|---|---|---|---|---|\n");
      for (const ConvergenceRow& r : bench_convergence(b, p, counts, 16))
        std::printf("| %.0e | %.4f | %.4g | %.4g | %.3f |\n", double(r.photons_per_row), r.seconds,
                    r.rel_l2_error, r.predicted, r.rms_z);
      std::fflush(stdout);
    }
  });

  auto* bake = cmd->add_subcommand("bake", "per-star optical-depth bake of a noise grid, CPU and CUDA");
  struct BakeOptions {
    std::string backends = "auto";
    int size = 256, stars = 4, repeats = 5;
  };
  auto b = std::make_shared<BakeOptions>();
  bake->add_option("--backend", b->backends, "cpu, cuda, both or auto")->capture_default_str();
  bake->add_option("--size", b->size, "voxels per grid edge")->capture_default_str();
  bake->add_option("--stars", b->stars, "stars (one inside the grid, the others outside)")
      ->capture_default_str();
  bake->add_option("--repeats", b->repeats, "timed runs after the warm-up")->capture_default_str();
  bake->callback([b] {
    if (b->size < 2 || b->size > 1024) throw Error("--size: must be 2 to 1024");
    if (b->stars < 1 || b->stars > 64) throw Error("--stars: must be 1 to 64");
    if (b->repeats < 1) throw Error("--repeats: must be at least 1");
    std::vector<Backend> backends;
    if (b->backends == "both" || (b->backends == "auto" && gpu_available()))
      backends = {Backend::Cpu, Backend::Cuda};
    else
      backends = {parse_backend(b->backends)};
    std::printf("| backend | grid | stars | bake s (median of %d) | star-voxels/s |\n|---|---|---|---|---|\n",
                b->repeats);
    for (Backend backend : backends) {
      // The CPU bakes one star (then scales): a 256^3 bake per star takes minutes on 2 cores.
      const int stars = backend == Backend::Cpu ? 1 : b->stars;
      const BakeBenchResult r = bench_bake(backend, b->size, stars, backend == Backend::Cpu ? 1 : b->repeats);
      std::printf("| %s | %d^3 | %d | %.4f | %.3g |\n", r.backend.c_str(), r.size, r.stars, r.median_seconds,
                  r.voxels_per_second);
      std::fflush(stdout);
    }
  });

  auto* rend = cmd->add_subcommand("render", "frames of the procedural nebula, 1 to N stars, CPU and CUDA");
  struct RenderOptions {
    std::string backends = "auto";
    int size = 256, width = 1920, height = 1080, stars = 8, repeats = 5;
  };
  auto r = std::make_shared<RenderOptions>();
  rend->add_option("--backend", r->backends, "cpu, cuda, both or auto")->capture_default_str();
  rend->add_option("--size", r->size, "voxels per grid edge")->capture_default_str();
  rend->add_option("--width", r->width, "image width")->capture_default_str();
  rend->add_option("--height", r->height, "image height")->capture_default_str();
  rend->add_option("--stars", r->stars, "largest star count (1, 2, 4, ... up to this)")->capture_default_str();
  rend->add_option("--repeats", r->repeats, "timed frames after the warm-up")->capture_default_str();
  rend->callback([r] {
    if (r->size < 2 || r->size > 1024) throw Error("--size: must be 2 to 1024");
    if (r->width < 1 || r->height < 1) throw Error("--width/--height: must be positive");
    if (r->stars < 1 || r->stars > 16) throw Error("--stars: must be 1 to 16");
    std::vector<Backend> backends;
    if (r->backends == "both" || (r->backends == "auto" && gpu_available()))
      backends = {Backend::Cpu, Backend::Cuda};
    else
      backends = {parse_backend(r->backends)};
    std::printf("| backend | image | grid | stars | ms per frame (median of %d) | rays/s |\n|---|---|---|---|---|---|\n",
                r->repeats);
    for (Backend backend : backends) {
      // The CPU renders a 1/10 x 1/10 image (same rays per second, minutes less).
      const int w = backend == Backend::Cpu ? std::max(1, r->width / 10) : r->width;
      const int h = backend == Backend::Cpu ? std::max(1, r->height / 10) : r->height;
      for (const RenderBenchRow& row : bench_render(backend, r->size, w, h, r->stars, r->repeats))
        std::printf("| %s | %dx%d | %d^3 | %d | %.3f | %.3g |\n", row.backend.c_str(), row.width, row.height,
                    row.size, row.stars, 1e3 * row.median_seconds, row.rays_per_second);
      std::fflush(stdout);
    }
  });

  auto* pyr = cmd->add_subcommand("pyramid", "the cost of each pyramid level on the procedural nebula, one star");
  struct PyramidOptions {
    std::string backend = "auto";
    int size = 256, width = 1920, height = 1080, levels = 3, repeats = 5;
  };
  auto p = std::make_shared<PyramidOptions>();
  pyr->add_option("--backend", p->backend, "cpu, cuda or auto")->capture_default_str();
  pyr->add_option("--size", p->size, "voxels per grid edge")->capture_default_str();
  pyr->add_option("--width", p->width, "image width")->capture_default_str();
  pyr->add_option("--height", p->height, "image height")->capture_default_str();
  pyr->add_option("--levels", p->levels, "coarser levels")->capture_default_str();
  pyr->add_option("--repeats", p->repeats, "timed frames after the warm-up")->capture_default_str();
  pyr->callback([p] {
    if (p->size < 4 || p->size > 1024) throw Error("--size: must be 4 to 1024");
    if (p->width < 1 || p->height < 1) throw Error("--width/--height: must be positive");
    if (p->repeats < 1) throw Error("--repeats: must be at least 1");
    const Backend backend = parse_backend(p->backend);
    const PyramidBench b = bench_pyramid(backend, p->size, p->width, p->height, p->levels, p->repeats);
    std::printf("pyramid on %s, procedural nebula %d^3, 1 star, level-0 bake %.2f ms\n", b.backend.c_str(), b.size,
                1e3 * b.bake_seconds);
    std::printf("| level | grid | image | build ms | bake ms | render ms (median of %d) | frame ms with levels 0..j |\n"
                "|---|---|---|---|---|---|---|\n",
                p->repeats);
    double frame = 0;
    for (const PyramidLevelReport& r : b.levels) {
      frame += r.render_seconds;
      std::printf("| %d | %dx%dx%d | %dx%d | %.2f | %.2f | %.3f | %.3f |\n", r.level, r.shape.nx, r.shape.ny,
                  r.shape.nz, r.width, r.height, 1e3 * r.pyramid_seconds, 1e3 * r.bake_seconds,
                  1e3 * r.render_seconds, 1e3 * (frame + (r.level > 0 ? b.combine_seconds : 0)));
    }
    std::printf("combination (down, clipped difference, up, add; on the %s): %.3f ms per frame\n", b.backend.c_str(),
                1e3 * b.combine_seconds);
  });

  auto* truth = cmd->add_subcommand("truth", "path tracer throughput on the procedural nebula: path vertices/s, spp/s");
  struct TruthOptions {
    std::string backends = "auto";
    int size = 256, width = 1920, height = 1080, spp = 16, repeats = 3;
    std::string transmittance = "both";
    bool equiangular = false;
  };
  auto t = std::make_shared<TruthOptions>();
  truth->add_option("--backend", t->backends, "cpu, cuda, both or auto")->capture_default_str();
  truth->add_option("--size", t->size, "voxels per grid edge")->capture_default_str();
  truth->add_option("--width", t->width, "image width")->capture_default_str();
  truth->add_option("--height", t->height, "image height")->capture_default_str();
  truth->add_option("--spp", t->spp, "samples per pixel (and band) per timed run")->capture_default_str();
  truth->add_option("--repeats", t->repeats, "timed runs after the warm-up")->capture_default_str();
  truth->add_option("--transmittance", t->transmittance, "next-event transmittance: ratio, exact or both")
      ->capture_default_str();
  truth->add_flag("--equiangular", t->equiangular, "with equiangular next-event estimation (MIS)");
  truth->callback([t] {
    if (t->transmittance != "ratio" && t->transmittance != "exact" && t->transmittance != "both")
      throw Error("--transmittance: expected ratio, exact or both, got '" + t->transmittance + "'");
    if (t->size < 2 || t->size > 1024) throw Error("--size: must be 2 to 1024");
    if (t->width < 1 || t->height < 1) throw Error("--width/--height: must be positive");
    if (t->spp < 2) throw Error("--spp: must be at least 2");
    if (t->repeats < 1) throw Error("--repeats: must be at least 1");
    std::vector<Backend> backends;
    if (t->backends == "both" || (t->backends == "auto" && gpu_available()))
      backends = {Backend::Cpu, Backend::Cuda};
    else
      backends = {parse_backend(t->backends)};
    std::printf("| backend | transmittance | image | grid | spp | s per run (median of %d) | path vertices/s | "
                "paths/s | spp/s at this size | spp/s at 1920x1080 | vertices/path |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n",
                t->repeats);
    std::vector<bool> modes;
    if (t->transmittance != "exact") modes.push_back(false);
    if (t->transmittance != "ratio") modes.push_back(true);
    for (Backend backend : backends)
      for (bool exact : modes) {
        // The CPU traces a 1/10 x 1/10 image at 2 spp (same rates per path, minutes less).
        const bool cpu = backend == Backend::Cpu;
        const int w = cpu ? std::max(1, t->width / 10) : t->width, h = cpu ? std::max(1, t->height / 10) : t->height;
        const TruthBenchRow row = bench_truth(backend, t->size, w, h, cpu ? 2 : t->spp, cpu ? 1 : t->repeats, exact,
                                              t->equiangular);
        // spp/s at 1920x1080: the same paths per second spread over 1920x1080 pixels.
        std::printf("| %s | %s | %dx%d | %d^3 | %d | %.4f | %.3g | %.3g | %.3g | %.3g | %.2f |\n", row.backend.c_str(),
                    exact ? (t->equiangular ? "exact+equiangular" : "exact")
                          : (t->equiangular ? "ratio+equiangular" : "ratio"),
                    row.width, row.height, row.size, row.spp, row.median_seconds,
                    row.vertices_per_second, row.paths_per_second, row.spp_per_second,
                    row.spp_per_second * double(row.width) * row.height / (1920.0 * 1080.0), row.vertices_per_path);
        std::fflush(stdout);
      }
  });

  auto* ax = cmd->add_subcommand("axial", "axial maps: every skip mode on every synthetic map, 0 to 90 degrees "
                                          "(Khalass 2021, Tables 5.1-5.5)");
  struct AxialOptions {
    std::string backends = "auto", maps = "bipolar,lopsided,shells,empty,full", inclinations = "0,15,30,45,60,75,90";
    std::string modes = "all";
    int map_size = 1024, image = 2048, repeats = 5;
    float step = 0.5f;
    bool emission_only = false, step_aside = true;
  };
  auto x = std::make_shared<AxialOptions>();
  ax->add_option("--backend", x->backends, "cpu, cuda, both or auto")->capture_default_str();
  ax->add_option("--map-size", x->map_size, "texels along the axis and radially")->capture_default_str();
  ax->add_option("--image", x->image, "image width and height, pixels (the CPU renders 1/8 of it per side)")
      ->capture_default_str();
  ax->add_option("--repeats", x->repeats, "timed frames after the warm-up")->capture_default_str();
  ax->add_option("--step", x->step, "march step, texels")->capture_default_str();
  ax->add_option("--maps", x->maps, "comma-separated synthetic maps")->capture_default_str();
  ax->add_option("--inclinations", x->inclinations, "comma-separated degrees from the axis")->capture_default_str();
  ax->add_option("--modes", x->modes, "comma-separated skip modes, or all (naive always runs, first)")
      ->capture_default_str();
  ax->add_flag("--emission-only", x->emission_only, "no star: the thesis' emission-absorption model only");
  ax->add_flag("!--no-step-aside", x->step_aside,
               "run the skip code even on maps without empty texels (its overhead on the full map)");
  ax->callback([x] {
    if (x->map_size < 2 || x->map_size > 16384) throw Error("--map-size: must be 2 to 16384");
    if (x->image < 1 || x->image > 16384) throw Error("--image: must be 1 to 16384");
    if (x->repeats < 1) throw Error("--repeats: must be at least 1");
    if (!(x->step >= 1e-3f && x->step <= 100)) throw Error("--step: must be in [1e-3, 100] texels");
    auto split = [](const std::string& text) {
      std::vector<std::string> out;
      size_t begin = 0;
      while (begin <= text.size()) {
        const size_t comma = text.find(',', begin);
        out.push_back(text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
        if (comma == std::string::npos) break;
        begin = comma + 1;
      }
      return out;
    };
    const std::vector<std::string> maps = split(x->maps);
    for (const std::string& m : maps) {
      const auto& known = synthetic_axial_map_names();
      if (std::find(known.begin(), known.end(), m) == known.end())
        throw Error("--maps: '" + m + "' is not a synthetic map (known: bipolar, lopsided, shells, empty, full)");
    }
    std::vector<int> inclinations;
    for (const std::string& t : split(x->inclinations)) {
      char* end = nullptr;
      const long v = std::strtol(t.c_str(), &end, 10);
      if (t.empty() || *end != '\0' || v < 0 || v > 90) throw Error("--inclinations: '" + t + "' is not a whole degree in 0..90");
      inclinations.push_back(int(v));
    }
    std::vector<AxialSkip> modes;
    if (x->modes != "all")
      for (const std::string& m : split(x->modes)) modes.push_back(parse_axial_skip(m, "--modes"));
    std::vector<Backend> backends;
    if (x->backends == "both" || (x->backends == "auto" && gpu_available()))
      backends = {Backend::Cpu, Backend::Cuda};
    else
      backends = {parse_backend(x->backends)};
    for (Backend backend : backends) {
      const int image = backend == Backend::Cpu ? std::max(1, x->image / 8) : x->image;
      std::printf("\naxial maps, %s%s: map %d x %d texels, image %d x %d, step %g texel, %s; ms median of %d after a warm-up\n",
                  to_string(backend), backend == Backend::Cuda ? (" (" + gpu_description() + ")").c_str() : "",
                  x->map_size, x->map_size, image, image, x->step,
                  x->emission_only ? "emission-absorption" : "one star on the axis (full physics)", x->repeats);
      std::printf("| map | inclination | mode | ran | ms | speed-up vs naive | max diff / peak | samples |\n"
                  "|---|---|---|---|---|---|---|---|\n");
      bench_axial(backend, x->map_size, image, image, x->repeats, x->step, maps, inclinations, !x->emission_only,
                  [](const AxialBenchRow& r) {
                    std::printf("| %s | %d | %s | %s | %.3f | %.2f | %.3g | %llu |\n", r.map.c_str(), r.inclination_deg,
                                r.mode.c_str(), r.ran.c_str(), r.median_ms, r.speedup, r.max_difference,
                                (unsigned long long)r.samples);
                    std::fflush(stdout);
                  },
                  x->step_aside, modes);
    }
  });
}

}  // namespace nebula::app
