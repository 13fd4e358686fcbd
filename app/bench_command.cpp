// `nebula bench ...`: the speed studies of validation/benchmarks.h, one
// subcommand each, printed as the Markdown tables of docs/performance.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "axial/axial_renderer.h"
#include "core/error.h"
#include "core/gpu.h"
#include "imageio/image_output.h"
#include "validation/benchmarks.h"

namespace nebula::app {
namespace {

// Options every benchmark has.
struct Common {
  std::string backends = "auto";
  int repeats = 5;
};

CLI::App* add_bench(CLI::App* bench, const char* name, const char* what, Common& c) {
  CLI::App* cmd = bench->add_subcommand(name, what);
  cmd->add_option("--backend", c.backends, "cpu, cuda, both or auto (= both when a GPU is present)")
      ->capture_default_str();
  cmd->add_option("--repeats", c.repeats, "timed runs after the warm-up")->capture_default_str()->check(CLI::PositiveNumber);
  return cmd;
}

void add_size(CLI::App* cmd, int& size, int smallest) {
  cmd->add_option("--size", size, "voxels per grid edge")->capture_default_str()->check(CLI::Range(smallest, 1024));
}

void add_frame(CLI::App* cmd, int& width, int& height) {
  cmd->add_option("--width", width, "image width")->capture_default_str()->check(CLI::Range(1, 65536));
  cmd->add_option("--height", height, "image height")->capture_default_str()->check(CLI::Range(1, 65536));
}

void add_tabulate(CLI::App* bench) {
  struct Options : Common {
    int tau_bins = 1000;
    std::string photons = "1e6";
    bool convergence = true;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = add_bench(bench, "tabulate",
                            "photons and scattering events per second, CPU and CUDA; table error against photons per row", *o);
  cmd->add_option("--tau-bins", o->tau_bins, "rows of the GPU table")->capture_default_str()->check(CLI::Range(2, 100000));
  cmd->add_option("--photons", o->photons, "photons per row of the GPU table")->capture_default_str();
  cmd->add_flag("!--no-convergence", o->convergence, "skip the error-against-photons study");
  cmd->callback([o] {
    const uint64_t gpu_photons = parse_count("--photons", o->photons, 2, double(kMaxPhotonsPerRow));
    const std::vector<Backend> backends = bench_backends(o->backends);
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
}

void add_bake(CLI::App* bench) {
  struct Options : Common {
    int size = 256, stars = 4;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = add_bench(bench, "bake", "per-star optical-depth bake of a noise grid, CPU and CUDA", *o);
  add_size(cmd, o->size, 2);
  cmd->add_option("--stars", o->stars, "stars (one inside the grid, the others outside)")
      ->capture_default_str()->check(CLI::Range(1, 64));
  cmd->callback([o] {
    std::printf("| backend | grid | stars | bake s (median of %d) | star-voxels/s |\n|---|---|---|---|---|\n",
                o->repeats);
    for (Backend backend : bench_backends(o->backends)) {
      // The CPU bakes one star (then scales): a 256^3 bake per star takes minutes on 2 cores.
      const bool cpu = backend == Backend::Cpu;
      const BakeBenchResult r = bench_bake(backend, o->size, cpu ? 1 : o->stars, cpu ? 1 : o->repeats);
      std::printf("| %s | %d^3 | %d | %.4f | %.3g |\n", r.backend.c_str(), r.size, r.stars, r.median_seconds,
                  r.voxels_per_second);
      std::fflush(stdout);
    }
  });
}

void add_render(CLI::App* bench) {
  struct Options : Common {
    int size = 256, width = 1920, height = 1080, stars = 8;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = add_bench(bench, "render", "frames of the procedural nebula, 1 to N stars, CPU and CUDA", *o);
  add_size(cmd, o->size, 2);
  add_frame(cmd, o->width, o->height);
  cmd->add_option("--stars", o->stars, "largest star count (1, 2, 4, ... up to this)")
      ->capture_default_str()->check(CLI::Range(1, 16));
  cmd->callback([o] {
    std::printf("| backend | image | grid | stars | ms per frame (median of %d) | rays/s |\n|---|---|---|---|---|---|\n",
                o->repeats);
    for (Backend backend : bench_backends(o->backends)) {
      // The CPU renders a 1/10 x 1/10 image (same rays per second, minutes less).
      const bool cpu = backend == Backend::Cpu;
      const int w = cpu ? std::max(1, o->width / 10) : o->width, h = cpu ? std::max(1, o->height / 10) : o->height;
      for (const RenderBenchRow& row : bench_render(backend, o->size, w, h, o->stars, o->repeats))
        std::printf("| %s | %dx%d | %d^3 | %d | %.3f | %.3g |\n", row.backend.c_str(), row.width, row.height,
                    row.size, row.stars, 1e3 * row.median_seconds, row.rays_per_second);
      std::fflush(stdout);
    }
  });
}

void add_diffuse(CLI::App* bench) {
  struct Options : Common {
    int size = 256, width = 1920, height = 1080, degree = -1, cells = 64, zonal = 0;  // degree -1: as "auto"
    std::string photons = "1048576";
    bool no_star_pixels = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = add_bench(bench, "diffuse",
                            "the diffuse field on the procedural nebula, one star: bake time, frames without and with "
                            "it, memory",
                            *o);
  add_size(cmd, o->size, 2);
  add_frame(cmd, o->width, o->height);
  cmd->add_option("--order", o->degree, "harmonics' degree (default: 4, or 3 with --zonal, as a scene's \"auto\")")
      ->check(CLI::Range(0, kMaxDiffuseDegree));
  cmd->add_option("--zonal", o->zonal, "zonal degrees of the star's light (0: none)")->capture_default_str()->check(CLI::Range(0, kMaxZonalDegree));
  cmd->add_option("--cells", o->cells, "field cells along the grid's edge (at least)")->capture_default_str()->check(CLI::Range(1, 4096));
  cmd->add_option("--photons", o->photons, "photons per band")->capture_default_str();
  cmd->add_flag("--no-star-pixels", o->no_star_pixels,
                "one ray per pixel at the star's image too (render.star_pixels = false): what the star's own pixels cost");
  cmd->callback([o] {
    const uint64_t photons = parse_count("--photons", o->photons, 1, 4294967295.0);
    if (o->degree < 0) o->degree = o->zonal > 0 ? 3 : 4;  // scene/scene.cpp, resolved_order
    std::printf("| backend | grid | field cells | order | photons/band | star bake ms | photon passes ms | diffuse bake "
                "ms (end to end) | frame ms without | frame ms with | field MiB | bake work MiB | star depth MiB | "
                "noise (V, l = 0) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (Backend backend : bench_backends(o->backends)) {
      // The CPU renders a 1/10 x 1/10 image (same rays per second, minutes less).
      const bool cpu = backend == Backend::Cpu;
      const int w = cpu ? std::max(1, o->width / 10) : o->width, h = cpu ? std::max(1, o->height / 10) : o->height;
      const DiffuseBench b = bench_diffuse(backend, o->size, w, h, cpu ? 1 : o->repeats, o->degree, o->cells, photons, o->zonal,
                                           !o->no_star_pixels);
      std::printf("| %s | %d^3 | %d^3 | %d | %llu | %.2f | %.2f | %.2f | %.3f (%dx%d) | %.3f | %.1f | %.1f | %.1f | %.2g%% |\n",
                  b.backend.c_str(), b.size, b.cells, b.degree, (unsigned long long)b.photons, 1e3 * b.star_bake_seconds,
                  1e3 * b.photon_seconds, 1e3 * b.bake_wall_seconds, 1e3 * b.frame_without, b.width, b.height,
                  1e3 * b.frame_with, b.field_bytes / 1048576.0, b.work_bytes / 1048576.0,
                  b.star_depth_bytes / 1048576.0, 100 * b.noise);
      std::fflush(stdout);
    }
  });
}

void add_pyramid(CLI::App* bench) {
  struct Options : Common {
    int size = 256, width = 1920, height = 1080, levels = 3;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd =
      add_bench(bench, "pyramid", "the cost of each pyramid level on the procedural nebula, one star", *o);
  add_size(cmd, o->size, 4);
  add_frame(cmd, o->width, o->height);
  cmd->add_option("--levels", o->levels, "coarser levels")->capture_default_str()->check(CLI::Range(0, 16));
  cmd->callback([o] {
    // One backend (auto: the GPU when present): the CPU at full size takes minutes per level.
    for (Backend backend : {parse_backend(o->backends)}) {
      const PyramidBench b = bench_pyramid(backend, o->size, o->width, o->height, o->levels, o->repeats);
      std::printf("pyramid on %s, procedural nebula %d^3, 1 star, level-0 bake %.2f ms\n", b.backend.c_str(), b.size,
                  1e3 * b.bake_seconds);
      std::printf("| level | grid | image | build ms | bake ms | render ms (median of %d) | frame ms with levels 0..j |\n"
                  "|---|---|---|---|---|---|---|\n",
                  o->repeats);
      double frame = 0;
      for (const PyramidLevelReport& r : b.levels) {
        frame += r.render_seconds;
        std::printf("| %d | %dx%dx%d | %dx%d | %.2f | %.2f | %.3f | %.3f |\n", r.level, r.shape.nx, r.shape.ny,
                    r.shape.nz, r.width, r.height, 1e3 * r.pyramid_seconds, 1e3 * r.bake_seconds,
                    1e3 * r.render_seconds, 1e3 * (frame + (r.level > 0 ? b.combine_seconds : 0)));
      }
      std::printf("combination (down, clipped difference, up, add; on the %s): %.3f ms per frame\n\n",
                  b.backend.c_str(), 1e3 * b.combine_seconds);
    }
  });
}

void add_truth(CLI::App* bench) {
  struct Options : Common {
    int size = 256, width = 1920, height = 1080, spp = 16, threads_per_pixel = 0;
    std::string transmittance = "both";
    bool equiangular = false;
  };
  auto o = std::make_shared<Options>();
  o->repeats = 3;
  CLI::App* cmd = add_bench(bench, "truth",
                            "path tracer throughput on the procedural nebula: path vertices/s, spp/s", *o);
  add_size(cmd, o->size, 2);
  add_frame(cmd, o->width, o->height);
  cmd->add_option("--spp", o->spp, "samples per pixel (and band) per timed run")
      ->capture_default_str()->check(CLI::Range(2, 10000000));
  cmd->add_option("--transmittance", o->transmittance, "next-event transmittance: ratio, exact or both")
      ->capture_default_str()->check(CLI::IsMember({"ratio", "exact", "both"}));
  cmd->add_flag("--equiangular", o->equiangular, "with equiangular next-event estimation (MIS)");
  cmd->add_option("--threads-per-pixel", o->threads_per_pixel,
                  "CUDA threads sharing each pixel's samples (0: as many as fill the GPU)")
      ->capture_default_str()->check(CLI::Range(0, 1 << 20));
  cmd->callback([o] {
    std::printf("| backend | transmittance | image | grid | spp | threads/pixel | s per run (median of %d) | "
                "path vertices/s | paths/s | spp/s at this size | spp/s at 1920x1080 | vertices/path |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                o->repeats);
    std::vector<bool> exact_modes;
    if (o->transmittance != "exact") exact_modes.push_back(false);
    if (o->transmittance != "ratio") exact_modes.push_back(true);
    for (Backend backend : bench_backends(o->backends))
      for (bool exact : exact_modes) {
        // The CPU traces a 1/10 x 1/10 image at 2 spp (same rates per path, minutes less).
        const bool cpu = backend == Backend::Cpu;
        const int w = cpu ? std::max(1, o->width / 10) : o->width, h = cpu ? std::max(1, o->height / 10) : o->height;
        const TruthBenchRow row =
            bench_truth(backend, o->size, w, h, cpu ? 2 : o->spp, cpu ? 1 : o->repeats, exact, o->equiangular,
                        o->threads_per_pixel);
        // spp/s at 1920x1080: the same paths per second spread over 1920x1080 pixels.
        std::printf("| %s | %s%s | %dx%d | %d^3 | %d | %d | %.4f | %.3g | %.3g | %.3g | %.3g | %.2f |\n",
                    row.backend.c_str(), exact ? "exact" : "ratio", o->equiangular ? "+equiangular" : "", row.width,
                    row.height, row.size, row.spp, row.threads_per_pixel, row.median_seconds, row.vertices_per_second, row.paths_per_second,
                    row.spp_per_second, row.spp_per_second * double(row.width) * row.height / (1920.0 * 1080.0),
                    row.vertices_per_path);
        std::fflush(stdout);
      }
  });
}

// The thesis' Tables 5.1-5.5 (Khalass 2021, RTX 2080 Ti, emission-absorption,
// 1024^2 map, 2048^2 image), as /work/shared/REFERENCES.md quotes them: per
// synthetic map its thesis case and the speed-ups over the naive march the
// thesis reports, without and with deformations ("" where it gives none).
struct ThesisCell {
  const char* map;
  AxialSkip mode;
  const char* plain;
  const char* deformed;
  double plain_ratio, deformed_ratio;  // 0: no number to compare with
};
const ThesisCell kThesisCells[] = {
    {"bipolar", AxialSkip::Naive, "34.9 ms", "", 0, 0},
    {"bipolar", AxialSkip::ThesisOmegaMax, "15.3x", "", 15.3, 0},
    {"bipolar", AxialSkip::ThesisOmegaLarge, "8.4x", "", 8.4, 0},
    {"bipolar", AxialSkip::ThesisOmegaMulti, "34.9x (1.0 ms)", "35.1x", 34.9, 35.1},
    {"lopsided", AxialSkip::ThesisOmegaMulti, "16.4x", "22.9x", 16.4, 22.9},
    {"shells", AxialSkip::ThesisOmegaMulti, "5.3x", "6.3x", 5.3, 6.3},
    {"empty", AxialSkip::ThesisOmegaMax, "< 1 ms (> 35x)", "", 0, 0},
    {"empty", AxialSkip::ThesisOmegaLarge, "9.8x", "", 9.8, 0},
    {"empty", AxialSkip::ThesisOmegaMulti, "< 1 ms (> 35x)", "", 0, 0},
    {"full", AxialSkip::Empty, "0.7x", "", 0.7, 0},
    {"full", AxialSkip::ThesisOmegaMax, "0.7x", "", 0.7, 0},
    {"full", AxialSkip::ThesisOmegaLarge, "0.7x", "", 0.7, 0},
    {"full", AxialSkip::ThesisOmegaMulti, "0.7x", "", 0.7, 0},
};

const char* thesis_case(const std::string& map) {
  if (map == "bipolar") return "thin, like M2-9";
  if (map == "lopsided") return "like the Calabash nebula";
  if (map == "shells") return "round, like NGC 6826";
  if (map == "empty") return "the empty map";
  return "the full map";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Tables 5.1-5.5 beside ours: per map, per mode, the median over the
// inclinations of our speed-up (and time), without and with deformations.
void print_thesis_tables(const std::vector<AxialBenchRow>& rows, const std::vector<std::string>& maps,
                         const std::vector<AxialSkip>& modes) {
  std::printf("\nKhalass 2021 Tables 5.1-5.5 beside ours: speed-up over the naive march (median over the inclinations; "
              "time in brackets). Thesis: RTX 2080 Ti, emission-absorption, 1024^2 map, 2048^2 image, its deformations; "
              "ours: this run. ours/thesis: our speed-up over the thesis' (goal: within 1/1.5 to 1.5).\n");
  for (const std::string& map : maps) {
    double empty = 0;
    for (const AxialBenchRow& r : rows)
      if (r.map == map) empty = r.empty_fraction;
    std::printf("\n%s (%s): %.1f%% of its texels empty\n\n", map.c_str(), thesis_case(map), 100.0 * empty);
    std::printf("| mode | thesis, no deformations | thesis, with deformations | ours, no deformations | "
                "ours, with deformations | ours/thesis, no def. | ours/thesis, with def. |\n"
                "|---|---|---|---|---|---|---|\n");
    for (AxialSkip mode : modes) {
      const ThesisCell* cell = nullptr;
      for (const ThesisCell& c : kThesisCells)
        if (map == c.map && mode == c.mode) cell = &c;
      std::string ours[2], versus[2];
      for (int d = 0; d < 2; ++d) {
        std::vector<double> speedups, ms;
        for (const AxialBenchRow& r : rows)
          if (r.map == map && r.mode == to_string(mode) && r.deformed == (d == 1)) {
            speedups.push_back(r.speedup);
            ms.push_back(r.median_ms);
          }
        if (speedups.empty()) {
          ours[d] = "-";
          continue;
        }
        char text[96];
        if (mode == AxialSkip::Naive)
          std::snprintf(text, sizeof text, "%.3g ms", median(ms));
        else
          std::snprintf(text, sizeof text, "%.3gx (%.3g ms)", median(speedups), median(ms));
        ours[d] = text;
        const double thesis = cell ? (d == 0 ? cell->plain_ratio : cell->deformed_ratio) : 0;
        if (thesis > 0) {
          std::snprintf(text, sizeof text, "%.2f", median(speedups) / thesis);
          versus[d] = text;
        }
      }
      const char* plain = cell && *cell->plain ? cell->plain : "-";
      const char* deformed = cell && *cell->deformed ? cell->deformed : "-";
      std::printf("| %s | %s | %s | %s | %s | %s | %s |\n", to_string(mode), plain, deformed, ours[0].c_str(),
                  ours[1].c_str(), versus[0].empty() ? "-" : versus[0].c_str(),
                  versus[1].empty() ? "-" : versus[1].c_str());
    }
  }
  std::fflush(stdout);
}

void add_axial(CLI::App* bench) {
  struct Options : Common {
    std::vector<std::string> maps{"bipolar", "lopsided", "shells", "empty", "full"}, modes;
    std::vector<int> inclinations{0, 15, 30, 45, 60, 75, 90};
    int map_size = 1024, image = 2048;
    float step = 0.5f;
    bool emission_only = false, step_aside = true, diffuse = false, no_star_pixels = false;
    std::string deform = "both", noise = "fbm", write_maps;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = add_bench(bench, "axial",
                            "axial maps: every skip mode on every synthetic map, 0 to 90 degrees, without and with "
                            "deformations (Khalass 2021, Tables 5.1-5.5, printed beside ours at the end)",
                            *o);
  cmd->add_option("--map-size", o->map_size, "texels along the axis and radially")
      ->capture_default_str()->check(CLI::Range(2, 16384));
  cmd->add_option("--image", o->image, "image width and height, pixels (the CPU renders 1/8 of it per side)")
      ->capture_default_str()->check(CLI::Range(1, 16384));
  cmd->add_option("--step", o->step, "march step, texels (the thesis: 1)")->capture_default_str()->check(CLI::Range(1e-3, 100.0));
  cmd->add_option("--maps", o->maps, "comma-separated synthetic maps")
      ->delimiter(',')->capture_default_str()->check(CLI::IsMember(synthetic_axial_map_names()));
  cmd->add_option("--inclinations", o->inclinations, "comma-separated whole degrees from the axis")
      ->delimiter(',')->capture_default_str()->check(CLI::Range(0, 90));
  cmd->add_option("--modes", o->modes, "comma-separated skip modes (default: all; naive always runs, first)")
      ->delimiter(',');
  cmd->add_flag("--emission-only", o->emission_only, "no star: the thesis' emission-absorption model only");
  cmd->add_flag("--diffuse", o->diffuse,
                "with the star, the map's diffuse field (light scattered between cells; its bake timed once per map)");
  cmd->add_flag("!--no-step-aside", o->step_aside,
                "run the skip code even on maps without empty texels (its overhead on the full map)");
  cmd->add_option("--deform", o->deform,
                  "off, on, both (off, then on), colour or shape (on, that kind only): the colour and shape "
                  "deformations (colour amplitude 0.5, pull up to 0.2, frequency 4 per map length, 4 octaves)")
      ->capture_default_str()->check(CLI::IsMember({"off", "on", "both", "colour", "shape"}));
  cmd->add_option("--noise", o->noise, "the deformations' noise: simplex, fbm, turbulence or cellular")
      ->capture_default_str()->check(CLI::IsMember({"simplex", "fbm", "turbulence", "cellular"}));
  cmd->add_flag("--no-star-pixels", o->no_star_pixels,
                "with the star, one ray per pixel at its image too (render.star_pixels = false): what its own pixels cost");
  cmd->add_option("--write-maps", o->write_maps,
                  "write each map as FOLDER/<map>.h5 first (bands tau_v, B, V, R; the bottom row is the axis: "
                  "what [axial] image = ... reads back)");
  cmd->callback([o] {
    std::vector<AxialSkip> modes;
    for (const std::string& m : o->modes) modes.push_back(parse_axial_skip(m, "--modes"));
    if (!o->write_maps.empty()) {
      if (!std::filesystem::is_directory(o->write_maps))
        throw Error("--write-maps: '" + o->write_maps + "' is not a folder");
      for (const std::string& name : o->maps) {
        // The benchmark's own map (bench_axial's sizes and densities).
        const AxialMap map = synthetic_axial_map(name, o->map_size, o->map_size, 1.0f / o->map_size, 3, 2.0f);
        Image image(map.nx, map.nr, {"tau_v", "B", "V", "R"});
        for (int ir = 0; ir < map.nr; ++ir)
          for (int ix = 0; ix < map.nx; ++ix) {
            const size_t i = map.index(ix, ir);
            const int y = map.nr - 1 - ir;
            image.at(0, ix, y) = map.tau_v[i];
            for (int b = 0; b < 3; ++b) image.at(b + 1, ix, y) = map.emission[size_t(b)][i];
          }
        const std::string path = (std::filesystem::path(o->write_maps) / (name + ".h5")).string();
        write_image(image, path, ImageMetadata{}, true);
        std::printf("wrote %s (%d x %d texels, %.1f%% empty)\n", path.c_str(), map.nx, map.nr,
                    100.0 * double(map.empty_texels) / double(map.count()));
      }
    }
    NoiseKind kind = NoiseKind::Fbm;
    parse_noise_kind(o->noise, kind);
    std::vector<AxialDeformSettings> deforms;
    if (o->deform == "off" || o->deform == "both") deforms.push_back(AxialDeformSettings{});
    if (o->deform != "off") {
      AxialDeformSettings d = bench_axial_deformations(kind);
      d.colour = o->deform != "shape";
      d.shape = o->deform != "colour";
      deforms.push_back(d);
    }
    for (Backend backend : bench_backends(o->backends)) {
      const int image = backend == Backend::Cpu ? std::max(1, o->image / 8) : o->image;
      std::printf("\naxial maps, %s%s: map %d x %d texels, image %d x %d, step %g texel, %s; deformations %s (%s "
                  "noise); ms median of %d after a warm-up\n",
                  to_string(backend), backend == Backend::Cuda ? (" (" + gpu_description() + ")").c_str() : "",
                  o->map_size, o->map_size, image, image, o->step,
                  o->emission_only ? "emission-absorption"
                  : o->diffuse     ? "one star on the axis (full physics) and the diffuse field"
                                   : "one star on the axis (full physics)",
                  o->deform.c_str(), o->noise.c_str(), o->repeats);
      std::printf("| map | empty texels | deformed | inclination | mode | ran | ms | speed-up vs naive | max diff / peak | "
                  "samples | diffuse bake ms |\n"
                  "|---|---|---|---|---|---|---|---|---|---|---|\n");
      std::vector<AxialBenchRow> rows;
      bench_axial(backend, o->map_size, image, image, o->repeats, o->step, o->maps, o->inclinations, !o->emission_only,
                  [&rows](const AxialBenchRow& r) {
                    std::printf("| %s | %.1f%% | %s | %d | %s | %s | %.3f | %.2f | %.3g | %llu | %.1f |\n",
                                r.map.c_str(), 100.0 * r.empty_fraction, r.deformed ? "yes" : "no",
                                r.inclination_deg, r.mode.c_str(), r.ran.c_str(), r.median_ms, r.speedup,
                                r.max_difference, (unsigned long long)r.samples, r.diffuse_bake_ms);
                    std::fflush(stdout);
                    rows.push_back(r);
                  },
                  o->step_aside, modes, o->diffuse, deforms, !o->no_star_pixels);
      std::vector<AxialSkip> shown = modes.empty() ? axial_skip_modes() : modes;
      shown.erase(std::remove(shown.begin(), shown.end(), AxialSkip::Naive), shown.end());
      shown.insert(shown.begin(), AxialSkip::Naive);
      print_thesis_tables(rows, o->maps, shown);
    }
  });
}


// Issue 16's sweep goal: a parameter study in one `nebula sweep` against the
// same points as separate `nebula render` runs, both as a user runs them
// (whole processes: start-up, scene load, bakes, render, file written), the
// tables generated once beforehand so that neither side pays for them.
void add_sweep(CLI::App* bench) {
  struct Options : Common {
    std::string scene = "scenes/fig12_reference.toml", albedos = "0.3:0.9:7", gs = "0,0.3,0.6,0.9";
    std::string table_photons = "3e4", work = "";
    int width = 512, height = 512;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = add_bench(bench, "sweep",
                            "an albedo x g sweep in one `nebula sweep` against separate `nebula render` runs", *o);
  cmd->add_option("--scene", o->scene, "the scene")->capture_default_str();
  cmd->add_option("--albedos", o->albedos, "dust.albedo values (START:STOP:COUNT or a list)")->capture_default_str();
  cmd->add_option("--gs", o->gs, "dust.g values")->capture_default_str();
  add_frame(cmd, o->width, o->height);
  cmd->add_option("--table-photons", o->table_photons, "photons per row of the tables (made once, before timing)")
      ->capture_default_str();
  cmd->add_option("--work", o->work, "folder for the images (default: a temporary one)");
  cmd->callback([o] {
    const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
    const std::string work = o->work.empty() ? (std::filesystem::temp_directory_path() / "nebula_bench_sweep").string()
                                             : o->work;
    std::filesystem::create_directories(work);
    const CubeAxis albedo = parse_grid_axis("dust.albedo=" + o->albedos), g = parse_grid_axis("dust.g=" + o->gs);
    auto run = [](const std::string& command) {
      const auto t0 = std::chrono::steady_clock::now();
      if (std::system((command + " > /dev/null").c_str()) != 0) throw Error("bench sweep: failed: " + command);
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    const std::string frame = " --width " + std::to_string(o->width) + " --height " + std::to_string(o->height) +
                              " --table-photons " + o->table_photons + " -q --force";
    for (Backend backend : bench_backends(o->backends)) {
      const std::string b = std::string(" --backend ") + to_string(backend);
      // The tables, once: a 1-pixel render of every point generates and caches them.
      double tables = 0;
      for (double a : albedo.values)
        for (double gv : g.values)
          tables += run(self + " render " + o->scene + " --set dust.albedo=" + to_text(a) + " --set dust.g=" +
                        to_text(gv) + " --set render.multiple_scattering=none --width 1 --height 1 --table-photons " +
                        o->table_photons + " -q --force -o " + work + "/table.fits" + b);
      double separate = 0;
      size_t i = 0;
      for (double a : albedo.values)
        for (double gv : g.values)
          separate += run(self + " render " + o->scene + " --set dust.albedo=" + to_text(a) + " --set dust.g=" +
                          to_text(gv) + frame + " -o " + work + "/point" + std::to_string(i++) + ".fits" + b);
      const std::string sweep_command = self + " sweep " + o->scene + " --grid dust.albedo=" + o->albedos +
                                        " --grid dust.g=" + o->gs + frame + b;
      const double sweep = run(sweep_command + " -o " + work + "/cube.fits");
      const double own = run(sweep_command + " --separate-photons -o " + work + "/cube_own.fits");
      std::vector<Image> points;
      for (size_t k = 0; k < albedo.values.size() * g.values.size(); ++k)
        points.push_back(read_image(work + "/point" + std::to_string(k) + ".fits"));
      // A cube against the separate images, point by point: the largest pixel
      // difference over the peak, and the largest difference of a point's total.
      auto compare = [&](const std::string& file, double& worst_pixel, double& worst_total) {
        const std::vector<Image> cube = read_fits_cube(file);
        if (cube.size() != points.size())
          throw Error("bench sweep: " + file + " has " + std::to_string(cube.size()) + " points");
        double worst = 0, peak = 0;
        worst_total = 0;
        for (size_t k = 0; k < points.size(); ++k) {
          double a = 0, b = 0;
          for (size_t p = 0; p < points[k].pixels.size(); ++p) {
            worst = std::max(worst, double(std::fabs(cube[k].pixels[p] - points[k].pixels[p])));
            peak = std::max(peak, double(points[k].pixels[p]));
            a += cube[k].pixels[p];
            b += points[k].pixels[p];
          }
          if (b > 0) worst_total = std::max(worst_total, std::fabs(a / b - 1));
        }
        worst_pixel = peak > 0 ? worst / peak : 0.0;
      };
      double shared_pixel, shared_total, own_pixel, own_total;
      compare(work + "/cube.fits", shared_pixel, shared_total);
      compare(work + "/cube_own.fits", own_pixel, own_total);
      const size_t n = points.size();
      std::printf("\nsweep, %s%s: %s, %zu points (albedo x %zu, g x %zu), %d x %d\n", to_string(backend),
                  backend == Backend::Cuda ? (" (" + gpu_description() + ")").c_str() : "", o->scene.c_str(), n,
                  albedo.values.size(), g.values.size(), o->width, o->height);
      std::printf("| tables made beforehand s | %zu separate renders s | one sweep s | one sweep, --separate-photons s "
                  "| s per point: separate, sweep | speed-up | speed-up, --separate-photons | sweep against separate: "
                  "max pixel / peak, max total | --separate-photons: max pixel / peak |\n"
                  "|---|---|---|---|---|---|---|---|---|\n| %.1f | %.2f | %.2f | %.2f | %.3f, %.3f | **%.2f** | %.2f | "
                  "%.3g, %.3g | %.3g |\n",
                  n, tables, separate, sweep, own, separate / n, sweep / n, separate / sweep, separate / own,
                  shared_pixel, shared_total, own_pixel);
      std::fflush(stdout);
    }
  });
}
}  // namespace

void add_bench_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("bench", "measure speed (medians after a warm-up)");
  cmd->require_subcommand(1);
  add_tabulate(cmd);
  add_bake(cmd);
  add_render(cmd);
  add_diffuse(cmd);
  add_pyramid(cmd);
  add_truth(cmd);
  add_axial(cmd);
  add_frame_benchmarks(cmd);  // app/bench_frames.cpp: animate, viewer
  add_sweep(cmd);
  add_spectral_bench(cmd);
  add_reconstruct_bench(cmd);
}

}  // namespace nebula::app
