// `nebula filters` (the filters scenes may name, with their sources and fits)
// and `nebula bench spectral` (the spectral methods' error and time against
// the double numerical integral on one scene, in one run: docs/spectral.md).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "app/commands.h"
#include "core/gpu.h"
#include "core/philox.h"
#include "illumination/filters.h"
#include "illumination/optical_depth_bake.h"
#include "pipeline/run_setup.h"
#include "spectral/piecewise_polynomial.h"
#include "spectral/spectral_renderer.h"
#include "spectral/two_column_file.h"

namespace nebula::app {
namespace {

void print_filter(const std::string& name, const Passband& p, const std::string& source) {
  spectral::FitReport r;
  spectral::fit_passband(p, 2e-3, &r);
  std::printf("%-11s %7.1f %7.1f %7.1f  %3d  %.1e  %s\n", name.c_str(), p.wavelength_nm.front(), p.wavelength_nm.back(),
              pipeline_detail::pivot_wavelength_nm(p), r.segments, r.max_error, source.c_str());
}

// fBm-like noise dust: octaves of Philox value noise, the report's kind of scene.
DensityGrid noise_grid(int n, float peak_tau) {
  DensityGrid g;
  g.shape.nx = g.shape.ny = g.shape.nz = n;
  g.shape.voxel = 1.0f / n;
  g.shape.origin = {-0.5f, -0.5f, -0.5f};
  g.tau_v.assign(g.shape.count(), 0.0f);
  for (int octave = 0, cells = 4; cells <= n; ++octave, cells *= 2)
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const int cx = x * cells / n, cy = y * cells / n, cz = z * cells / n;
          const float v = philox_uniform4(5, uint32_t(octave), uint32_t((cz * cells + cy) * cells + cx), 0, 0).u0;
          g.tau_v[g.shape.index(x, y, z)] += peak_tau * v / float(1 << octave) * 0.5f;
        }
  return g;
}

}  // namespace

void add_filters_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("filters", "list the filters scenes may name, with their source and polynomial fit");
  auto file = std::make_shared<std::string>();
  cmd->add_option("--file", *file, "check a user filter file (two columns: wavelength_nm response) and show its fit");
  cmd->callback([file] {
    std::printf("%-11s %7s %7s %7s  %3s  %7s  %s\n", "name", "from_nm", "to_nm", "pivot", "seg", "fit_err", "source");
    if (!file->empty()) {
      print_filter(*file, spectral::load_filter_file(*file), "user file");
      return;
    }
    for (const FilterInfo& f : known_filters()) print_filter(f.name, load_filter(f.name), f.source);
    std::printf("fit_err: largest |piecewise cubic - measured curve| / peak (docs/spectral.md)\n");
  });
}

void add_spectral_bench(CLI::App* bench) {
  auto* cmd = bench->add_subcommand("spectral", "spectral methods against the double numerical integral (error, time)");
  struct Options {
    std::string backends = "auto";
    int size = 64, width = 256, height = 256, repeats = 3, stars = 1;
    float tau = 4.0f;
    std::vector<std::string> filters{"B", "V", "R"};
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--backend", o->backends, "cpu, cuda, both or auto")->capture_default_str();
  cmd->add_option("--size", o->size, "voxels per edge of the noise cube")->capture_default_str();
  cmd->add_option("--width", o->width)->capture_default_str();
  cmd->add_option("--height", o->height)->capture_default_str();
  cmd->add_option("--stars", o->stars, "stars of different temperatures (1-6)")->capture_default_str();
  cmd->add_option("--tau", o->tau, "largest tau_V per voxel of the noise")->capture_default_str();
  cmd->add_option("--filters", o->filters)->capture_default_str();
  cmd->add_option("--repeats", o->repeats)->capture_default_str();
  cmd->callback([o] {
    std::vector<Backend> backends;
    std::string why;
    const bool gpu = gpu_available(&why);
    if (o->backends == "cpu" || o->backends == "both" || (o->backends == "auto")) backends.push_back(Backend::Cpu);
    if (o->backends == "cuda" || o->backends == "both" || (o->backends == "auto" && gpu)) backends.push_back(Backend::Cuda);
    const DensityGrid grid = noise_grid(o->size, o->tau);
    const double temps[6] = {41400, 31400, 15700, 9700, 5770, 3850};
    const Vec3 where[6] = {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}, {0.2f, -0.3f, 0.1f},
                           {-0.1f, 0.3f, -0.3f}, {0.3f, 0.1f, 0.3f}, {0.0f, -0.1f, 0.0f}};
    const int S = std::clamp(o->stars, 1, 6);
    std::vector<Vec3> positions(where, where + S);
    const BakeResult bake = bake_star_depths(grid, positions, gpu ? Backend::Cuda : Backend::Cpu);
    std::vector<std::pair<std::string, Passband>> filters;
    for (const std::string& f : o->filters) filters.push_back({f, load_filter(f)});
    std::vector<spectral::SpectralStar> stars;
    for (int k = 0; k < S; ++k) stars.push_back({temps[k]});
    CameraSettings cs;
    cs.position = {0.3f, -2.5f, -2.0f};
    cs.look_at = {0, 0, 0};
    cs.up = {0, 0, 1};
    cs.fov_deg = 40;
    cs.width = o->width;
    cs.height = o->height;
    const Camera camera = make_camera(cs);
    const auto inputs = [&](const spectral::SpectralModel& m) {
      spectral::SpectralRenderInputs in;
      in.density = &grid;
      in.model = &m;
      for (int k = 0; k < S; ++k) in.lights.push_back({positions[k], 100.0, &bake.tau_v[k]});
      in.camera = camera;
      return in;
    };
    std::printf("noise cube %d^3 (tau_V per voxel up to %.2g), %dx%d, %d star(s), %zu filters\n", o->size, o->tau,
                o->width, o->height, S, filters.size());
    for (Backend backend : backends) {
      const auto run = [&](const spectral::SpectralModel& m, Image* out) {
        std::vector<double> times;
        for (int r = 0; r < o->repeats + 1; ++r) {
          double s = 0;
          const auto start = std::chrono::steady_clock::now();
          const Image acc = spectral::render_spectral(inputs(m), backend, &s);
          const Image img = spectral::resolve_filters(acc, m);
          const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (r > 0) times.push_back(backend == Backend::Cuda ? s : wall);
          if (out) *out = img;
        }
        std::sort(times.begin(), times.end());
        return times[times.size() / 2];
      };
      spectral::SpectralSettings ref_settings;
      ref_settings.method = spectral::SpectralMethod::Double;
      ref_settings.wavelengths = 400;
      Image ref;
      const double ref_time = run(spectral::build_spectral_model(filters, stars, ref_settings), &ref);
      double peak = 0;
      for (float v : ref.pixels) peak = std::max(peak, double(v));
      const auto errors = [&](const Image& img) {
        double worst = 0, sum = 0, count = 0;
        for (size_t i = 0; i < ref.pixels.size(); ++i)
          if (ref.pixels[i] > 1e-3 * peak) {
            const double e = std::fabs(img.pixels[i] - ref.pixels[i]) / ref.pixels[i];
            worst = std::max(worst, e);
            sum += e;
            ++count;
          }
        return std::pair<double, double>{worst, count > 0 ? sum / count : 0};
      };
      std::printf("[%s] reference: double integral, M = 400 wavelengths: %.2f ms\n",
                  backend == Backend::Cuda ? "cuda" : "cpu", ref_time * 1e3);
      std::printf("%-26s %9s %9s %11s %11s\n", "method", "ms", "speedup", "max_err", "mean_err");
      const auto row = [&](const char* name, spectral::SpectralSettings s) {
        Image img;
        const double t = run(spectral::build_spectral_model(filters, stars, s), &img);
        const auto [worst, mean] = errors(img);
        std::printf("%-26s %9.2f %9.1f %11.2e %11.2e\n", name, t * 1e3, ref_time / t, worst, mean);
      };
      spectral::SpectralSettings s;
      s.method = spectral::SpectralMethod::Double;
      s.wavelengths = 20;
      row("double, M = 20", s);
      s.method = spectral::SpectralMethod::Analytic;
      row("analytic (Algorithm 1)", s);
      for (int n = 1; n <= 6; ++n) {
        s.method = spectral::SpectralMethod::Projection;
        s.basis = n;
        if (S * n <= spectral::kMaxAccumulators) row(("projection, N = " + std::to_string(n)).c_str(), s);
      }
      for (int n = 2; n <= 8; n += 2) {
        s.method = spectral::SpectralMethod::LightBasis;
        s.basis = n;
        row(("light basis, N = " + std::to_string(n)).c_str(), s);
      }
    }
  });
}

}  // namespace nebula::app
