// `nebula sweep SCENE --grid KEY=SPEC ...`: one scene over a grid of values
// of scene keys, to a FITS or HDF5 cube (pipeline/sweep.h), reusing the work
// the swept keys do not touch.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/print_report.h"
#include "core/error.h"
#include "core/progress.h"
#include "montecarlo/tabulate.h"
#include "pipeline/sweep.h"

namespace nebula::app {
namespace {

struct Options {
  std::string scene, out, backend = "auto", table_photons = "3e4";
  std::vector<std::string> overrides, grids;
  int width = -1, height = -1, spp = 64;
  uint64_t seed = 1;
  bool truth = false, force = false, quiet = false, separate_photons = false;
};

double number(const std::string& spec, const std::string& text) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size() || !std::isfinite(v))
    throw Error("--grid '" + spec + "': '" + text + "' is not a number");
  return v;
}

}  // namespace

// KEY=START:STOP:COUNT (COUNT values evenly spaced, both ends included) or
// KEY=V1,V2,... (a list).
CubeAxis parse_grid_axis(const std::string& spec) {
  const size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--grid '" + spec + "': expected KEY=START:STOP:COUNT or KEY=V1,V2,...");
  CubeAxis axis{spec.substr(0, eq), {}};
  const std::string values = spec.substr(eq + 1);
  if (values.empty()) throw Error("--grid '" + spec + "': no values (an empty range)");
  if (values.find(':') != std::string::npos) {
    std::vector<std::string> parts;
    size_t from = 0;
    for (size_t at; (at = values.find(':', from)) != std::string::npos; from = at + 1)
      parts.push_back(values.substr(from, at - from));
    parts.push_back(values.substr(from));
    if (parts.size() != 3) throw Error("--grid '" + spec + "': a range is START:STOP:COUNT");
    const double start = number(spec, parts[0]), stop = number(spec, parts[1]), count = number(spec, parts[2]);
    if (!(count >= 1) || count != std::floor(count))
      throw Error("--grid '" + spec + "': COUNT must be a whole number of at least 1 (an empty range otherwise)");
    if (count > double(kMaxSweepPoints)) throw Error("--grid '" + spec + "': COUNT over " + std::to_string(kMaxSweepPoints));
    if (count == 1 && start != stop) throw Error("--grid '" + spec + "': one value needs START = STOP");
    const int n = int(count);
    for (int i = 0; i < n; ++i) axis.values.push_back(n == 1 ? start : start + (stop - start) * i / (n - 1));
  } else {
    size_t from = 0;
    for (;;) {
      const size_t at = values.find(',', from);
      axis.values.push_back(number(spec, values.substr(from, at == std::string::npos ? std::string::npos : at - from)));
      if (at == std::string::npos) break;
      from = at + 1;
    }
  }
  return axis;
}

namespace {

void run_sweep_command(const Options& o) {
  if (o.grids.empty()) throw Error("--grid: give at least one KEY=START:STOP:COUNT or KEY=V1,V2,...");
  std::vector<CubeAxis> axes;
  for (const std::string& g : o.grids) axes.push_back(parse_grid_axis(g));
  const std::string ext = o.out.size() >= 3 ? o.out.substr(o.out.rfind('.') == std::string::npos ? 0 : o.out.rfind('.')) : "";
  if (!(ext == ".fits" || ext == ".fit" || ext == ".h5"))
    throw Error("-o: " + o.out + ": a cube is written as .fits, .fit or .h5");
  check_output_path("-o", o.out, o.force);
  std::vector<std::string> overrides = o.overrides;
  if (o.width != -1) overrides.push_back("camera.width=" + std::to_string(o.width));
  if (o.height != -1) overrides.push_back("camera.height=" + std::to_string(o.height));
  RenderOptions options;
  options.backend = parse_backend(o.backend);
  options.table_photons = parse_count("--table-photons", o.table_photons, 1000, double(kMaxBasePhotons));
  RenderSession session = RenderSession::from_file(o.scene, overrides, options);
  check_not_an_input("-o", o.out, session.load().inputs);
  SweepOptions so;
  so.truth = o.truth;
  so.truth_options.backend = options.backend;
  so.truth_options.spp = o.spp;
  so.truth_options.seed = o.seed;
  so.force = o.force;
  so.share_photons = !o.separate_photons;
  double points = 1;
  for (const CubeAxis& a : axes) points *= double(a.values.size());
  if (points > double(kMaxSweepPoints) && !o.force)
    throw Error("--grid: " + to_text(points) + " points, more than " + std::to_string(kMaxSweepPoints) +
                "; --force runs them anyway");
  std::unique_ptr<Progress> bar;
  size_t done = 0;
  SweepResult r;
  naming_options({{"grid", "--grid"}, {"spp", "--spp"}, {"backend", "--backend"}}, [&] {
    r = run_sweep(session, axes, so, [&](size_t i, size_t n) {
      if (!bar && !o.quiet) bar = std::make_unique<Progress>("sweep", n);
      if (bar) bar->add(i - done);
      done = i;
    });
    if (bar) bar->finish();
    write_cube(r.images, r.axes, o.out, r.metadata, o.force);
  }, o.scene);
  size_t bakes = 0, fields = 0, reused_bakes = 0, reused_fields = 0, shared_fields = 0;
  for (const RunReport& rep : r.reports) {
    bakes += rep.bake.done;
    reused_bakes += rep.bake.reused;
    fields += rep.diffuse.done;
    reused_fields += rep.diffuse.reused;
    shared_fields += rep.diffuse.done && !rep.diffuse.reused && rep.diffuse.shared_with > 0;
  }
  // Where the points' time went (a shared bake's figures split between its members).
  double tables = 0, star_bakes = 0, fields_wall = 0, passes = 0, frames = 0, points_total = 0;
  for (const RunReport& rep : r.reports) {
    for (const TableReport& t : rep.tables) tables += t.seconds;
    if (rep.bake.done && !rep.bake.reused) star_bakes += rep.bake.seconds;
    if (rep.diffuse.done && !rep.diffuse.reused) {
      fields_wall += rep.diffuse.wall_seconds / (1 + rep.diffuse.shared_with);
      passes += rep.diffuse.seconds / (1 + rep.diffuse.shared_with);
    }
    frames += rep.render_seconds;
    points_total += rep.total_seconds;
  }
  std::printf("sweep: %zu points (", r.images.size());
  for (size_t k = 0; k < axes.size(); ++k)
    std::printf("%s%s x %zu", k ? ", " : "", axes[k].key.c_str(), axes[k].values.size());
  std::printf(") in %.3g s, %.3g s per point; %s\n", r.seconds, r.seconds / double(r.images.size()),
              o.truth ? "the ground truth" : "the fast renderer");
  if (!o.truth)
    std::printf("  reused: star bakes %zu of %zu, diffuse fields %zu of %zu; %zu field(s) from photon passes shared "
                "between albedos (--separate-photons: none); the rest computed for their point\n",
                reused_bakes, bakes, reused_fields, fields, shared_fields);
  if (!o.truth)
    std::printf("  time: %.3g s in the points' renders (tables %.3g, star bakes %.3g, diffuse fields %.3g of which "
                "photon passes %.3g, frames %.3g, the rest %.3g: scene loads, preparation, copies); %.3g s outside "
                "them (checking and planning every point, start-up)\n",
                points_total, tables, star_bakes, fields_wall, passes, frames,
                points_total - tables - star_bakes - fields_wall - frames, r.seconds - points_total);
  std::printf("wrote %s\n", o.out.c_str());
}

}  // namespace

void add_sweep_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("sweep", "render a scene over a grid of parameter values to a FITS or HDF5 cube");
  auto o = std::make_shared<Options>();
  cmd->add_option("scene", o->scene, "the scene file (TOML)")->required();
  cmd->add_option("--grid", o->grids,
                  "KEY=START:STOP:COUNT or KEY=V1,V2,... (repeatable; the first varies slowest), e.g. "
                  "--grid dust.albedo=0.3:0.9:7 --grid dust.g=0,0.3,0.6,0.9")
      ->allow_extra_args(false);
  cmd->add_option("-o,--output", o->out, "the cube: .fits or .h5")->required();
  cmd->add_option("--set", o->overrides, "KEY=VALUE override applied to every point (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--width", o->width, "image width in pixels (the scene's otherwise)");
  cmd->add_option("--height", o->height, "image height in pixels (the scene's otherwise)");
  cmd->add_flag("--truth", o->truth, "the ground truth (nebula truth) instead of the fast renderer");
  cmd->add_option("--spp", o->spp, "with --truth: samples per pixel and band")->capture_default_str();
  cmd->add_option("--seed", o->seed, "with --truth: the random seed")->capture_default_str();
  cmd->add_option("--backend", o->backend, "cpu, cuda or auto")->capture_default_str();
  cmd->add_option("--table-photons", o->table_photons, "photons per row for tables generated on first use (rows of tau_sct < 1 trace up to 32 times more; docs/tabulator.md)")
      ->capture_default_str();
  cmd->add_flag("--separate-photons", o->separate_photons,
                "every point bakes its diffuse field from photons of its own (each plane then equals a separate "
                "render bit for bit; slower). Default: points differing only in albedo share one photon pass");
  cmd->add_flag("--force", o->force, "overwrite an existing output; allow more than 100000 points");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress bar");
  cmd->callback([o] { run_sweep_command(*o); });
}

}  // namespace nebula::app
