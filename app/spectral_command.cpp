// `nebula filters` (the filters scenes may name, with their sources and fits)
// and `nebula bench spectral` (the spectral methods' error and time against
// the double numerical integral on one scene, in one run: docs/spectral.md).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <list>
#include <optional>
#include <thread>

#include "app/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/gpu.h"
#include "core/philox.h"
#include "illumination/filters.h"
#include "illumination/optical_depth_bake.h"
#include "pipeline/run_setup.h"
#include "pipeline/scene_bands.h"
#include "pipeline/spectral_scene.h"
#include "scene/scene_file.h"
#include "spectral/piecewise_polynomial.h"
#include "spectral/spectral_renderer.h"
#include "tables/table_file.h"
#include "illumination/filter_file.h"

namespace nebula::app {
namespace {

void print_filter(const std::string& name, const Passband& p, const std::string& source) {
  spectral::FitReport r;
  spectral::fit_passband(p, 2e-3, &r);
  std::printf("%-11s %7.1f %7.1f %7.1f  %3d  %.1e  %s\n", name.c_str(), p.wavelength_nm.front(), p.wavelength_nm.back(),
              pipeline_detail::pivot_wavelength_nm(p), r.segments, r.max_error, source.c_str());
}

// fBm-like noise dust (octaves of Philox value noise, amplitude halving per
// octave: the report's kind of scene), scaled so that the mean V-band optical
// depth across the cube is `tau_across`.
DensityGrid noise_grid(int n, float tau_across) {
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
          g.tau_v[g.shape.index(x, y, z)] += v / float(1 << octave);
        }
  double sum = 0;
  for (float v : g.tau_v) sum += v;
  const double scale = tau_across / (sum / double(g.tau_v.size()) * n);
  for (float& v : g.tau_v) v = float(v * scale);
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
      print_filter(*file, load_filter_file(*file), "user file");
      return;
    }
    for (const FilterInfo& f : known_filters()) print_filter(f.name, load_filter(f.name), f.source);
    std::printf("fit_err: largest |piecewise cubic - measured curve| / peak (docs/spectral.md)\n");
  });
}

namespace {

// What the bench renders: the noise cube or a scene file, as the spectral
// renderer's inputs.
struct BenchScene {
  std::string name;
  DensityGrid grid;
  std::vector<Vec3> positions;
  std::vector<double> luminosity, temperature;
  Camera camera;
  float albedo = 0.6f, g = 0.6f;
  double R_V = 5.0;
  ExtinctionLaw law = ExtinctionLaw::CCM89;
  std::vector<std::pair<std::string, Passband>> filters;
  // A scene's [[spectral.emission]] (its weight grids stay in `emission_grids`).
  std::vector<spectral::SpectralEmission> emission;
  std::vector<std::vector<float>> emission_grids;
  std::vector<float> emission_scale;
};

std::string cpu_description() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "CPU";
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return model + " (" + std::to_string(std::thread::hardware_concurrency()) + " threads)";
}

// JSON text of a string (names and device lines: printable ASCII).
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

struct BenchRow {
  std::string method, norm;
  int basis = 0, wavelengths = 0, table_nodes = 0;
  double ms = 0, speedup = 0, max_err = 0, mean_err = 0, p99_err = 0;
};

}  // namespace

void add_spectral_bench(CLI::App* bench) {
  auto* cmd = bench->add_subcommand(
      "spectral", "spectral methods against the double numerical integral (error, time; docs/spectral.md)");
  struct Options {
    std::string backends = "auto", scene, json, attenuation = "inverse", table;
    int table_nodes = 3;
    std::vector<std::string> overrides;
    int size = 64, width = 256, height = 256, repeats = 3, stars = 1, reference = 400;
    double near_voxels = spectral::SpectralSettings{}.near_voxels;
    float tau = 4.0f;
    bool quick = false, diffuse = false, no_star_pixels = false;
    std::vector<std::string> filters{"B", "V", "R"};
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--backend", o->backends, "cpu, cuda, both or auto")->capture_default_str();
  cmd->add_option("--scene", o->scene, "render this scene file's grid, stars, camera and bands instead of the noise cube");
  cmd->add_option("--set", o->overrides, "KEY=VALUE override of --scene (repeatable)");
  cmd->add_option("--size", o->size, "voxels per edge of the noise cube")->capture_default_str()->check(CLI::Range(2, 1024));
  CLI::Option* width = cmd->add_option("--width", o->width)->capture_default_str()->check(CLI::Range(1, 65536));
  CLI::Option* height = cmd->add_option("--height", o->height)->capture_default_str()->check(CLI::Range(1, 65536));
  cmd->add_option("--stars", o->stars, "noise cube: stars of different temperatures (1-6)")
      ->capture_default_str()
      ->check(CLI::Range(1, 6));
  cmd->add_option("--tau", o->tau, "noise cube: mean V-band optical depth across the cube")->capture_default_str();
  cmd->add_option("--filters", o->filters, "noise cube: the bands")->capture_default_str();
  cmd->add_option("--attenuation", o->attenuation, "inverse (C_T / lambda, the report's; analytic rows) or law")
      ->capture_default_str();
  cmd->add_option("--reference", o->reference, "wavelength samples of the reference double integral")
      ->capture_default_str()
      ->check(CLI::Range(2, 4096));
  cmd->add_option("--repeats", o->repeats)->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--near-voxels", o->near_voxels, "voxel light: pairs this close to a star (voxels) taken exactly")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_flag("--quick", o->quick,
                "fewer rows (double M = 20, projection N = 4, light basis N = 4 and 6, voxel light N = 4)");
  cmd->add_option("--table", o->table,
                  "the voxels' scattering table (an HDF5 file from `nebula tabulate`, for the dust's albedo and g): "
                  "every method reads it (docs/spectral.md, \"Tables\"); default: the thin-voxel limit");
  cmd->add_option("--table-nodes", o->table_nodes, "with --table: attenuations the table is read at")
      ->capture_default_str()
      ->check(CLI::Range(1, spectral::kMaxTableNodes));
  cmd->add_flag("--diffuse", o->diffuse,
                "with --scene and --table: every row with the light between voxels (the scene's render.diffuse_* "
                "settings), its field baked once and its per-view pass timed apart (docs/spectral.md)");
  cmd->add_flag("--no-star-pixels", o->no_star_pixels,
                "one ray per pixel at the stars' images too (render.star_pixels = false): the stars' own pixels "
                "take thousands of rays per star (docs/marcher.md), a cost that grows with the stars");
  cmd->add_option("--json", o->json, "also write the results as JSON to this file");
  cmd->callback([o, width, height] {
    if (o->attenuation != "inverse" && o->attenuation != "law")
      throw Error("--attenuation: '" + o->attenuation + "' is not inverse or law");
    if (!o->json.empty()) check_output_target(o->json, true, "folder", true);
    if (o->diffuse && (o->scene.empty() || o->table.empty()))
      throw Error("--diffuse: needs --scene (the field's settings and stars) and --table (the voxels' response)");
    std::vector<Backend> backends;
    std::string why;
    const bool gpu = gpu_available(&why);
    if (o->backends == "cpu" || o->backends == "both" || (o->backends == "auto")) backends.push_back(Backend::Cpu);
    if (o->backends == "cuda" || o->backends == "both" || (o->backends == "auto" && gpu)) backends.push_back(Backend::Cuda);
    if (!gpu && o->backends != "cpu" && o->backends != "auto") throw Error("--backend: no CUDA device (" + why + ")");

    BenchScene b;
    std::optional<Scene> loaded;
    if (!o->scene.empty()) {
      loaded = load_scene(o->scene, o->overrides);
      const Scene& scene = *loaded;
      if (scene.axial) throw Error(o->scene + ": the spectral bench renders 3D grids");
      b.name = o->scene;
      b.grid = scene.density;
      for (const SceneStar& s : scene.stars) {
        b.positions.push_back(s.position);
        b.luminosity.push_back(s.luminosity_lsun);
        b.temperature.push_back(s.temperature_K);
      }
      CameraSettings cs = scene.camera;
      if (width->count() > 0) cs.width = o->width;
      if (height->count() > 0) cs.height = o->height;
      b.camera = make_camera(cs);
      b.albedo = float(scene.dust.albedo.front());
      b.g = float(scene.dust.g.front());
      b.R_V = scene.dust.R_V;
      b.law = scene.dust.law;
      const SceneBands bands = scene_bands(scene);
      for (size_t i = 0; i < scene.bands.size(); ++i) b.filters.push_back({scene.bands[i], bands.filters[i]});
      if (scene.spectral) {
        for (const SpectralEmissionSpec& e : scene.spectral->emission) {
          b.emission.push_back({e.line_nm / 1000.0, e.continuum, e.lo_nm / 1000.0, e.hi_nm / 1000.0});
          b.emission_scale.push_back(float(e.scale));
        }
        b.emission_grids = scene.spectral->emission_grids;
        b.emission_grids.resize(b.emission.size());
      }
    } else {
      b.name = "noise cube " + std::to_string(o->size) + "^3, mean tau_V across " + to_text(o->tau);
      b.grid = noise_grid(o->size, o->tau);
      const double temps[6] = {41400, 31400, 15700, 9700, 5770, 3850};
      const Vec3 where[6] = {{0.1f, 0.2f, -0.1f}, {-0.3f, 0.0f, 0.2f}, {0.2f, -0.3f, 0.1f},
                             {-0.1f, 0.3f, -0.3f}, {0.3f, 0.1f, 0.3f}, {0.0f, -0.1f, 0.0f}};
      for (int k = 0; k < o->stars; ++k) {
        b.positions.push_back(where[k]);
        b.luminosity.push_back(100.0);
        b.temperature.push_back(temps[k]);
      }
      CameraSettings cs;
      cs.position = {0.3f, -2.5f, -2.0f};
      cs.look_at = {0, 0, 0};
      cs.up = {0, 0, 1};
      cs.fov_deg = 40;
      cs.width = o->width;
      cs.height = o->height;
      b.camera = make_camera(cs);
      for (const std::string& f : o->filters) b.filters.push_back({f, load_filter(f)});
    }
    std::optional<ScatteringTable> table;
    if (!o->table.empty()) {
      table = read_table(o->table);
      if (std::fabs(table->albedo - b.albedo) > 1e-6 || std::fabs(table->g - b.g) > 1e-6)
        throw Error("--table: " + o->table + " holds albedo " + to_text(table->albedo) + ", g " + to_text(table->g) +
                    "; the dust has albedo " + to_text(b.albedo) + ", g " + to_text(b.g));
    }
    BakeResult bake = bake_star_depths(b.grid, b.positions, gpu ? Backend::Cuda : Backend::Cpu);
    std::vector<spectral::SpectralStar> stars;
    for (double t : b.temperature) stars.push_back({t});
    const int S = int(stars.size());
    // --diffuse: the light between voxels for a model's table nodes (the same for every row
    // that reads the table at as many nodes), baked and projected for the camera once.
    std::list<std::pair<std::vector<double>, spectral::SpectralDiffuseLight>> lights;  // stable addresses
    const auto diffuse_light = [&](const spectral::SpectralModel& m) -> const spectral::SpectralDiffuseLight* {
      if (!o->diffuse || m.node_kappa.empty()) return nullptr;
      for (const auto& [nodes, light] : lights)
        if (nodes == m.node_kappa) return &light;
      RunReport report;
      RenderOptions options;
      options.backend = gpu ? Backend::Cuda : Backend::Cpu;
      double view = 0;
      const auto start = std::chrono::steady_clock::now();
      spectral::SpectralDiffuseLight light =
          spectral_diffuse_light(*loaded, m, std::vector<const ScatteringTable*>(m.node_kappa.size(), &*table), bake, b.camera, options, report, &view);
      std::printf("light between voxels at kappa =");
      for (double k : m.node_kappa) std::printf(" %.3g", k);
      std::printf(": %zu star(s) x %zu photons per node, fields %.3f s (photon passes %.3f s), per-view passes %.4f s "
                  "(%s; once per view, not in the rows' times, which hold the voxels' terms)\n",
                  report.diffuse.stars, size_t(report.diffuse.photons_per_band),
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - view,
                  report.diffuse.seconds, view, to_string(options.backend));
      lights.push_back({m.node_kappa, std::move(light)});
      return &lights.back().second;
    };
    // The first `stars` stars (all by default); the voxel-light buffers reused between frames.
    const auto inputs = [&](const spectral::SpectralModel& m, spectral::VoxelLightWorkspace* work = nullptr) {
      spectral::SpectralRenderInputs in;
      in.density = &b.grid;
      in.model = &m;
      in.workspace = work;
      for (int k = 0; k < m.n_stars; ++k) in.lights.push_back({b.positions[k], b.luminosity[k], &bake.tau_v[k]});
      in.albedo = b.albedo;
      in.g = b.g;
      in.camera = b.camera;
      in.table = table ? &*table : nullptr;
      in.star_pixels = !o->no_star_pixels;
      if (m.n_stars == S) in.diffuse = diffuse_light(m);
      for (size_t c = 0; c < b.emission.size(); ++c) {  // a grid (scale applied) or tau_V times the scale
        const bool grid = !b.emission_grids[c].empty();
        in.emission.push_back({grid ? &b.emission_grids[c] : nullptr, grid ? 1.0f : b.emission_scale[c]});
      }
      return in;
    };
    std::string filter_list;
    for (const auto& f : b.filters) filter_list += (filter_list.empty() ? "" : " ") + f.first;
    std::printf("%s: grid %dx%dx%d, %dx%d pixels, %d star(s), filters %s, attenuation %s, %s\n", b.name.c_str(),
                b.grid.shape.nx, b.grid.shape.ny, b.grid.shape.nz, b.camera.width, b.camera.height, S,
                filter_list.c_str(), o->attenuation.c_str(),
                table ? ("table " + o->table + " read at " + std::to_string(o->table_nodes) + " attenuations").c_str()
                      : "thin-voxel limit (no table)");
    std::printf("the stars' own pixels: %s\n", o->no_star_pixels ? "one ray each (--no-star-pixels)"
                                                                 : "many rays each (render.star_pixels)");
    if (!b.emission.empty())
      std::printf("emission: %zu component(s) from the scene's [[spectral.emission]], in every row\n", b.emission.size());
    std::string json = "{\n  \"scene\": " + json_string(b.name) + ",\n  \"emission_components\": " +
                       std::to_string(b.emission.size()) + ",\n  \"stars\": " + std::to_string(S) +
                       ",\n  \"star_pixels\": " + (o->no_star_pixels ? "false" : "true") +
                       ",\n  \"width\": " + std::to_string(b.camera.width) + ",\n  \"height\": " +
                       std::to_string(b.camera.height) + ",\n  \"filters\": " + json_string(filter_list) +
                       ",\n  \"attenuation\": " + json_string(o->attenuation) + ",\n  \"table\": " +
                       json_string(o->table) + ",\n  \"table_nodes\": " + std::to_string(table ? o->table_nodes : 0) +
                       ",\n  \"runs\": [";
    for (size_t bi = 0; bi < backends.size(); ++bi) {
      const Backend backend = backends[bi];
      // Median time of the march and the resolve (the march alone by CUDA events on the GPU;
      // the voxel-light method's pre-pass included, its buffers allocated in the warm-up).
      const auto run = [&](const spectral::SpectralModel& m, Image* out) {
        std::vector<double> times;
        spectral::VoxelLightWorkspace work;
        for (int r = 0; r < o->repeats + 1; ++r) {
          double s = 0;
          const auto start = std::chrono::steady_clock::now();
          const Image acc = spectral::render_spectral(inputs(m, &work), backend, &s);
          const Image img = spectral::resolve_filters(acc, m);
          const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (r > 0 || wall > 5.0) times.push_back(backend == Backend::Cuda ? s : wall);
          if (out) *out = img;
          if (wall > 5.0) break;  // a slow method: its first run is its time (no warm-up needed)
        }
        std::sort(times.begin(), times.end());
        return times[times.size() / 2];
      };
      spectral::SpectralSettings base;
      base.attenuation = o->attenuation == "law" ? spectral::Attenuation::Law : spectral::Attenuation::Inverse;
      base.R_V = b.R_V;
      base.law = b.law;
      base.near_voxels = o->near_voxels;
      base.table_nodes = table ? o->table_nodes : 0;  // the reference reads the table at each wavelength
      spectral::SpectralSettings ref_settings = base;
      ref_settings.method = spectral::SpectralMethod::Double;
      ref_settings.wavelengths = o->reference;
      Image ref;
      const double ref_time = run(spectral::build_spectral_model(b.filters, stars, ref_settings, b.emission), &ref);
      const size_t plane = ref.plane_size();
      // Relative error over pixels above 1e-3 of their band's peak: largest, mean, 99th percentile.
      const auto errors = [&](const Image& img, BenchRow& row) {
        std::vector<double> e;
        for (size_t f = 0; f < ref.bands.size(); ++f) {
          double peak = 0;
          for (size_t i = 0; i < plane; ++i) peak = std::max(peak, double(ref.pixels[f * plane + i]));
          for (size_t i = 0; i < plane; ++i) {
            const double r = ref.pixels[f * plane + i];
            if (r > 1e-3 * peak) e.push_back(std::fabs(img.pixels[f * plane + i] - r) / r);
          }
        }
        if (e.empty()) return;
        std::sort(e.begin(), e.end());
        double sum = 0;
        for (double v : e) sum += v;
        row.max_err = e.back();
        row.mean_err = sum / double(e.size());
        row.p99_err = e[std::min(e.size() - 1, size_t(0.99 * double(e.size())))];
      };
      const std::string device = backend == Backend::Cuda ? gpu_description() : cpu_description();
      std::printf("[%s] %s\nreference: double integral, M = %d wavelengths: %.2f ms\n",
                  backend == Backend::Cuda ? "cuda" : "cpu", device.c_str(), o->reference, ref_time * 1e3);
      std::printf("%-30s %9s %9s %10s %10s %10s\n", "method", "ms", "speedup", "max_err", "p99_err", "mean_err");
      std::vector<BenchRow> rows;
      const auto row = [&](const std::string& name, spectral::SpectralSettings s) {
        if (s.method == spectral::SpectralMethod::Projection && S * s.basis > spectral::kMaxAccumulators) return;
        Image img;
        BenchRow r;
        const spectral::SpectralModel m = spectral::build_spectral_model(b.filters, stars, s, b.emission);
        r.ms = run(m, &img) * 1e3;
        r.method = s.method == spectral::SpectralMethod::Double       ? "double"
                   : s.method == spectral::SpectralMethod::Analytic   ? "analytic"
                   : s.method == spectral::SpectralMethod::Projection ? "projection"
                   : s.method == spectral::SpectralMethod::LightBasis ? "light_density"
                   : s.method == spectral::SpectralMethod::Preintegrated ? "preintegrated"
                                                                         : "voxel_light";
        r.norm = s.relative ? "relative" : "absolute";
        r.basis = m.basis.size();
        r.table_nodes = table ? s.table_nodes : 0;
        r.wavelengths = s.method == spectral::SpectralMethod::Double ? s.wavelengths : 0;
        r.speedup = ref_time * 1e3 / r.ms;
        errors(img, r);
        std::printf("%-30s %9.2f %9.1f %10.2e %10.2e %10.2e\n", name.c_str(), r.ms, r.speedup, r.max_err, r.p99_err,
                    r.mean_err);
        rows.push_back(r);
      };
      spectral::SpectralSettings s = base;
      s.method = spectral::SpectralMethod::Double;
      for (int M : o->quick ? std::vector<int>{20} : std::vector<int>{10, 20, 40, 80}) {
        s.wavelengths = M;
        row("double, M = " + std::to_string(M), s);
      }
      if (base.attenuation == spectral::Attenuation::Inverse) {
        s.method = spectral::SpectralMethod::Analytic;
        row("analytic (Algorithm 1)", s);
      }
      s.method = spectral::SpectralMethod::Projection;
      for (int n : o->quick ? std::vector<int>{4} : std::vector<int>{1, 2, 3, 4, 5, 6}) {
        s.basis = n;
        row("projection, N = " + std::to_string(n), s);
      }
      if (table)  // the table's attenuations: their error against the reference's lookup at every wavelength
        for (int nodes = 1; nodes <= spectral::kMaxTableNodes; ++nodes)
          if (nodes != o->table_nodes) {
            s.basis = 4;
            s.table_nodes = nodes;
            row("projection, N = 4, " + std::to_string(nodes) + " node(s)", s);
          }
      s.table_nodes = base.table_nodes;
      s.relative = false;
      for (int n : o->quick ? std::vector<int>{} : std::vector<int>{3, 4}) {
        s.basis = n;
        row("projection absolute, N = " + std::to_string(n), s);
      }
      s.relative = true;
      s.method = spectral::SpectralMethod::LightBasis;
      for (int n : o->quick ? std::vector<int>{4, 6} : std::vector<int>{2, 4, 6, 8}) {
        s.basis = n;
        row("light basis, N = " + std::to_string(n), s);
      }
      s.method = spectral::SpectralMethod::VoxelLight;  // the per-view pre-pass: cost flat in the stars
      for (int n : o->quick ? std::vector<int>{4} : std::vector<int>{3, 4, 5}) {
        s.basis = n;
        row("voxel light, N = " + std::to_string(n), s);
      }
      s.method = spectral::SpectralMethod::Preintegrated;  // no basis: the integral tabulated over D
      row("pre-integrated", s);
      // Six spectra at the cost of one: each method with these stars against the same
      // method with the first star alone, frames alternated in one process (a shared
      // machine's load then weighs on both alike); medians of `repeats` pairs.
      std::string ratio_json;
      if (S > 1) {
        std::printf("%d stars against the first alone (same method, frames alternated):\n", S);
        std::printf("%-30s %9s %9s %9s\n", "method", "1 star ms", "all ms", "ratio");
        std::vector<spectral::SpectralStar> first(stars.begin(), stars.begin() + 1);
        for (const auto method : {spectral::SpectralMethod::Projection, spectral::SpectralMethod::LightBasis,
                                  spectral::SpectralMethod::VoxelLight, spectral::SpectralMethod::Preintegrated}) {
          spectral::SpectralSettings rs = base;
          rs.method = method;
          rs.basis = 4;
          if (method == spectral::SpectralMethod::Projection && S * rs.basis > spectral::kMaxAccumulators) continue;
          const spectral::SpectralModel one = spectral::build_spectral_model(b.filters, first, rs, b.emission);
          const spectral::SpectralModel all = spectral::build_spectral_model(b.filters, stars, rs, b.emission);
          spectral::VoxelLightWorkspace w1, wa;
          std::vector<double> t1, ta;
          for (int r = 0; r < o->repeats + 1; ++r)
            for (int which = 0; which < 2; ++which) {
              double sec = 0;
              const auto start = std::chrono::steady_clock::now();
              const Image acc = spectral::render_spectral(inputs(which ? all : one, which ? &wa : &w1), backend, &sec);
              const Image img = spectral::resolve_filters(acc, which ? all : one);
              const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
              if (r > 0) (which ? ta : t1).push_back(backend == Backend::Cuda ? sec : wall);
            }
          std::sort(t1.begin(), t1.end());
          std::sort(ta.begin(), ta.end());
          const double ms1 = t1[t1.size() / 2] * 1e3, msa = ta[ta.size() / 2] * 1e3;
          const std::string name = method == spectral::SpectralMethod::Projection      ? "projection"
                                   : method == spectral::SpectralMethod::LightBasis    ? "light_density"
                                   : method == spectral::SpectralMethod::Preintegrated ? "preintegrated"
                                                                                       : "voxel_light";
          std::printf("%-30s %9.2f %9.2f %9.3f\n",
                      (name + (method == spectral::SpectralMethod::Preintegrated ? "" : ", N = 4")).c_str(), ms1, msa,
                      msa / ms1);
          ratio_json += std::string(ratio_json.empty() ? "" : ",") + "\n       {\"method\": " + json_string(name) +
                        ", \"basis\": 4, \"one_star_ms\": " + to_text(ms1) + ", \"all_stars_ms\": " + to_text(msa) +
                        ", \"ratio\": " + to_text(msa / ms1) + "}";
        }
      }
      json += std::string(bi ? "," : "") + "\n    {\"backend\": " + json_string(backend == Backend::Cuda ? "cuda" : "cpu") +
              ", \"device\": " + json_string(device) + ", \"reference_wavelengths\": " + std::to_string(o->reference) +
              ", \"reference_ms\": " + to_text(ref_time * 1e3) + ",\n     \"rows\": [";
      for (size_t i = 0; i < rows.size(); ++i) {
        const BenchRow& r = rows[i];
        json += std::string(i ? "," : "") + "\n      {\"method\": " + json_string(r.method) + ", \"norm\": " +
                json_string(r.norm) + ", \"basis\": " + std::to_string(r.basis) + ", \"wavelengths\": " +
                std::to_string(r.wavelengths) + ", \"table_nodes\": " + std::to_string(r.table_nodes) +
                ", \"ms\": " + to_text(r.ms) + ", \"speedup\": " + to_text(r.speedup) +
                ", \"max_err\": " + to_text(r.max_err) + ", \"p99_err\": " + to_text(r.p99_err) +
                ", \"mean_err\": " + to_text(r.mean_err) + "}";
      }
      json += "],\n     \"star_ratios\": [" + ratio_json + "]}";
    }
    json += "\n  ]\n}\n";
    if (!o->json.empty()) {
      TemporaryFile tmp(o->json);
      std::ofstream(tmp.path()) << json;
      tmp.publish();
      std::printf("wrote %s\n", o->json.c_str());
    }
  });
}

}  // namespace nebula::app
