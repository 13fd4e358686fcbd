// `nebula reconstruct IMAGE --axis X,Y,ANGLE -o map.h5`: an axial map from
// one image (reconstruct/, docs/axial.md "Reconstruction"), and `nebula bench
// reconstruct`: the methods' time and errors on the synthetic maps.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "axial/axial_renderer.h"
#include "core/error.h"
#include "core/gpu.h"
#include "imageio/image_output.h"
#include "reconstruct/absorb_fit.h"
#include "reconstruct/projection.h"
#include "reconstruct/reconstruct.h"

namespace nebula::app {
namespace {

// The project's float files through read_image, every other format through
// OpenImageIO (as an [axial] image map is read).
Image read_input(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool ours = ext == ".h5" || ext == ".fits" || ext == ".fit" || ext == ".exr";
  return ours ? read_image(path) : read_any_image(path);
}

ImageAxis parse_axis(const std::vector<double>& v) {
  if (v.size() != 3) throw Error("--axis: expected X,Y,ANGLE (pixels from the top-left corner, degrees)");
  return {v[0], v[1], v[2]};
}

// The map rendered as the straightened image (one pixel per texel), the
// image's planes named as the input's.
Image render_map(const AxialMap& map, const std::vector<std::string>& bands, const std::vector<float>& ratio,
                 float step_texels, Backend backend) {
  AxialRenderInputs in;
  in.map = &map;
  for (size_t b = 0; b < bands.size(); ++b) {
    AxialRenderBand band;
    band.name = bands[b];
    band.extinction_ratio = ratio.empty() ? 1.0f : ratio[b];
    band.albedo = 0.0f;
    in.bands.push_back(band);
  }
  in.camera = straight_camera(map.nx, map.nr, map.texel);
  in.step = step_texels * map.texel;
  return render_axial(in, backend);
}

// Three panels, 4 pixels apart: the straightened input, the reconstructed
// map (mirrored about the axis, the way it is seen; its own scale) and the
// map re-rendered (the input's scale).
Image side_by_side(const StraightImage& s, const AxialMap& map, const Image& again) {
  const int gap = 4;
  Image out(3 * s.nx + 2 * gap, 2 * s.nr, s.bands);
  float peak = 0, map_peak = 0;
  for (size_t b = 0; b < s.bands.size(); ++b)
    for (int ix = 0; ix < s.nx; ++ix)
      for (int j = 0; j < s.nr; ++j) {
        const float v = s.column(int(b), ix)[j];
        out.at(int(b), ix, s.nr - 1 - j) = out.at(int(b), ix, s.nr + j) = v;
        peak = std::max(peak, v);
        map_peak = std::max(map_peak, map.emission[b][map.index(ix, j)]);
      }
  for (size_t b = 0; b < s.bands.size(); ++b)
    for (int ix = 0; ix < s.nx; ++ix)
      for (int j = 0; j < s.nr; ++j) {
        const float v = map_peak > 0 ? peak * map.emission[b][map.index(ix, j)] / map_peak : 0.0f;
        out.at(int(b), s.nx + gap + ix, s.nr - 1 - j) = out.at(int(b), s.nx + gap + ix, s.nr + j) = v;
      }
  for (size_t b = 0; b < s.bands.size(); ++b)
    for (int y = 0; y < again.height; ++y)
      for (int x = 0; x < again.width; ++x) out.at(int(b), 2 * (s.nx + gap) + x, y) = again.at(int(b), x, y);
  // A picture: noise below 0 shows as black.
  for (float& v : out.pixels) v = std::max(0.0f, peak > 0 ? v / peak : v);
  return out;
}

void run_reconstruct(const std::string& input, const std::vector<double>& axis_values, const std::string& out,
                     const std::string& method, const std::string& backend_text, int length, int radius,
                     const std::string& smoothness, float step, const std::vector<float>& ratios,
                     const std::string& compare, bool force) {
  ReconstructSettings s;
  s.method = parse_reconstruct_method(method, "--method");
  s.axis = parse_axis(axis_values);
  s.length = length;
  s.radius = radius;
  s.step_texels = step;
  s.extinction_ratio = ratios;
  if (smoothness == "auto") {
    s.smoothness = -1;
  } else {
    char* end = nullptr;
    s.smoothness = std::strtod(smoothness.c_str(), &end);
    if (smoothness.empty() || *end != '\0' || !(s.smoothness >= 0) || !std::isfinite(s.smoothness))
      throw Error("--smoothness: '" + smoothness + "' is neither a number >= 0 nor auto");
  }
  s.backend = parse_backend(backend_text);
  if (s.method != ReconstructMethod::Powell && backend_text == "auto") s.backend = Backend::Cpu;
  if (std::filesystem::path(out).extension() != ".h5") throw Error("-o: " + out + ": the map is an HDF5 file (.h5)");
  check_output_path("-o", out, force);
  if (!compare.empty()) check_image_output("--compare", compare, force);
  const Image image = read_input(input);
  const OptionNames names{{"axis", "--axis"}, {"length", "--length"}, {"radius", "--radius"},
                          {"smoothness", "--smoothness"}, {"step_texels", "--step"}, {"backend", "--backend"},
                          {"extinction_ratio", "--extinction-ratios"}, {"image", input}};
  naming_options(names, [&] {
    const StraightImage straight = straighten_image(image, s.axis, s.length, s.radius);
    ReconstructReport r;
    const AxialMap map = reconstruct_any(straight, s, &r);
    // Every output made before any is written: a failure leaves nothing behind.
    Image panels;
    if (!compare.empty()) {
      const Image again = render_map(map, image.bands, s.method == ReconstructMethod::Absorb ? s.extinction_ratio
                                                                                             : std::vector<float>{},
                                     s.step_texels, Backend::Cpu);
      panels = side_by_side(straight, map, again);
    }
    write_axial_map_hdf5(map, image.bands, out, force);
    std::printf("reconstructed %s: map %d x %d texels (one per pixel), %d band%s, method %s on %s\n", input.c_str(),
                r.nx, r.nr, r.bands, r.bands == 1 ? "" : "s", to_string(s.method),
                s.method == ReconstructMethod::Powell ? to_string(s.backend) : "cpu");
    std::printf("  forward model %.3f s, fit %.3f s; image error %.3g (||model - input|| / ||input||)\n",
                r.seconds_projection, r.seconds_solve, r.image_error);
    std::printf("  noise seen between the two sides %.3g per pixel; smoothness %g; %lld iterations; %d column%s "
                "stopped at the iteration limit\n",
                r.side_rms, r.smoothness, r.iterations, r.not_converged, r.not_converged == 1 ? "" : "s");
    if (!compare.empty()) {
      try {
        write_image(panels, compare, ImageMetadata{}, force);
      } catch (const Error&) {
        std::filesystem::remove(out);  // nothing half-done: the map goes with its picture
        throw;
      }
      std::printf("wrote %s (the input straightened | the map, own scale | the map re-rendered)\n", compare.c_str());
    }
  });
  std::printf("wrote %s: render it with [axial] file = \"%s\", emission_prefix = \"emission_\", "
              "length_pc = <nx times the pixel size in pc>, axis in the sky plane\n",
              out.c_str(), std::filesystem::path(out).filename().string().c_str());
}

// bench: one synthetic map per row, emission only, rendered at the thesis'
// inclination 0, then reconstructed by each method.
void run_bench(const std::string& backends, int size, const std::vector<std::string>& maps,
               const std::vector<std::string>& methods, double noise) {
  for (Backend backend : bench_backends(backends)) {
    std::printf("\nreconstruction, %s%s: map %d x %d texels from a %d x %d image, 3 bands, emission only, "
                "noise %g of the peak; against Khalass 2021: 6-58 s per 1024^2 map (RTX 2080 Ti)\n",
                to_string(backend), backend == Backend::Cuda ? (" (" + gpu_description() + ")").c_str() : "", size,
                size, size, 2 * size, noise);
    std::printf("| map | method | forward model s | fit s | total s | image error | map error | iterations |\n"
                "|---|---|---|---|---|---|---|---|\n");
    for (const std::string& name : maps) {
      AxialMap truth = synthetic_axial_map(name, size, size, 1.0f, 3);
      truth.origin = {0, 0, 0};
      truth.axis = {1, 0, 0};
      std::fill(truth.tau_v.begin(), truth.tau_v.end(), 0.0f);
      truth.update_skip_structures();
      Image image = render_map(truth, {"B", "V", "R"}, {}, 0.5f, backend);
      if (noise > 0) {
        float peak = 0;
        for (float v : image.pixels) peak = std::max(peak, v);
        std::mt19937 rng(1);
        std::normal_distribution<float> n(0.0f, float(noise) * peak);
        for (float& v : image.pixels) v += n(rng);
      }
      const StraightImage straight = straighten_image(image, {0.0, double(size), 0.0});
      for (const std::string& m : methods) {
        ReconstructSettings s;
        s.method = parse_reconstruct_method(m, "--methods");
        if (s.method != ReconstructMethod::Powell && backend == Backend::Cuda) continue;
        s.backend = backend;
        s.smoothness = noise > 0 ? -1.0 : 0.0;
        ReconstructReport r;
        const AxialMap got = reconstruct_any(straight, s, &r);
        double d = 0, t = 0;
        for (size_t b = 0; b < 3; ++b)
          for (size_t i = 0; i < truth.count(); ++i) {
            d += std::pow(double(got.emission[b][i]) - truth.emission[b][i], 2);
            t += std::pow(double(truth.emission[b][i]), 2);
          }
        std::printf("| %s | %s | %.3f | %.3f | %.3f | %.3g | %.3g | %lld |\n", name.c_str(), m.c_str(),
                    r.seconds_projection, r.seconds_solve, r.seconds_projection + r.seconds_solve, r.image_error,
                    std::sqrt(d / t), r.iterations);
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace

void add_reconstruct_command(CLI::App& app) {
  struct Options {
    std::string input, out, method = "nnls", backend = "auto", smoothness = "0", compare;
    std::vector<double> axis;
    std::vector<float> ratios;
    int length = 0, radius = 0;
    float step = 0.5f;
    bool force = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("reconstruct",
                                 "an axial map from one image of the nebula seen perpendicular to its axis "
                                 "(Khalass 2021; docs/axial.md)");
  cmd->add_option("IMAGE", o->input, "the image: .h5, .fits, .exr as nebula writes them, or PNG/TIFF/... (OpenImageIO)")
      ->required();
  cmd->add_option("--axis", o->axis,
                  "X,Y,ANGLE: where the map starts on the symmetry axis (pixels from the top-left corner) and "
                  "the axis' direction (degrees counter-clockwise from rightwards)")
      ->delimiter(',')->required();
  cmd->add_option("-o,--output", o->out, "the map, HDF5 (.h5), as [axial] file = ... reads it")->required();
  cmd->add_option("--method", o->method, "powell (the thesis'), nnls (ours) or absorb (ours, emission and tau_v)")
      ->capture_default_str();
  cmd->add_option("--backend", o->backend, "powell: cpu, cuda or auto; nnls and absorb run on the CPU")
      ->capture_default_str();
  cmd->add_option("--length", o->length, "texels along the axis (0: to the image's edge)")->capture_default_str();
  cmd->add_option("--radius", o->radius, "texels from the axis (0: to the image's nearer edge)")->capture_default_str();
  cmd->add_option("--smoothness", o->smoothness,
                  "Tikhonov weight of nnls and absorb, or auto (the discrepancy principle against the noise "
                  "the two sides show)")
      ->capture_default_str();
  cmd->add_option("--step", o->step, "the march step in texels the map will be rendered with")->capture_default_str();
  cmd->add_option("--extinction-ratios", o->ratios, "absorb: A_b / A_V per image band (default 1 each)")
      ->delimiter(',');
  cmd->add_option("--compare", o->compare, "also write an image: the straightened input | the map | the map re-rendered");
  cmd->add_flag("--force", o->force, "overwrite the outputs");
  cmd->callback([o] {
    run_reconstruct(o->input, o->axis, o->out, o->method, o->backend, o->length, o->radius, o->smoothness, o->step,
                    o->ratios, o->compare, o->force);
  });
}

void add_reconstruct_bench(CLI::App* bench) {
  struct Options {
    std::string backends = "auto";
    int size = 256;
    std::vector<std::string> maps{"bipolar", "lopsided", "shells"};
    std::vector<std::string> methods{"powell", "nnls"};
    double noise = 0;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = bench->add_subcommand("reconstruct", "reconstruction of the synthetic maps: time and errors per method "
                                                   "(against Khalass 2021's 6-58 s per 1024^2 map)");
  cmd->add_option("--backend", o->backends, "cpu, cuda, both or auto (= both when a GPU is present)")
      ->capture_default_str();
  cmd->add_option("--map-size", o->size, "texels along the axis and radially")->capture_default_str()
      ->check(CLI::Range(2, 4096));
  cmd->add_option("--maps", o->maps, "comma-separated synthetic maps")->delimiter(',')->capture_default_str()
      ->check(CLI::IsMember(synthetic_axial_map_names()));
  cmd->add_option("--methods", o->methods, "comma-separated: powell, nnls, absorb")->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--noise", o->noise, "Gaussian noise, a fraction of the image's peak (then smoothness auto)")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0));
  cmd->callback([o] { run_bench(o->backends, o->size, o->maps, o->methods, o->noise); });
}

}  // namespace nebula::app
