// `nebula compare A B`: image A against reference B, per band (validation/image_compare.h).
#include <cstdio>
#include <memory>
#include <string>
#include <sys/stat.h>

#include "app/cli_support.h"
#include "app/commands.h"
#include "core/error.h"
#include "imageio/image_output.h"
#include "validation/image_compare.h"

namespace nebula::app {
namespace {

bool exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

struct Options {
  std::string a, b, diff;
  bool json = false, force = false;
  double signal = 1e-3;
};

void run_compare(const Options& o) {
  if (!o.diff.empty()) {
    const auto dot = o.diff.rfind('.');
    if (dot == std::string::npos || o.diff.substr(dot) != ".png") throw Error("--diff: " + o.diff + ": must be a .png");
    if (!openimageio_available()) throw Error("--diff: " + o.diff + ": .png needs OpenImageIO, which this build lacks");
    check_output_path("--diff", o.diff, o.force);
  }
  const Image a = read_image(o.a), b = read_image(o.b);
  const std::string va = variance_path(o.a), vb = variance_path(o.b);
  Image var_a, var_b;
  const bool has_a = exists(va), has_b = exists(vb);
  if (has_a) var_a = read_image(va);
  if (has_b) var_b = read_image(vb);
  Comparison c;
  naming_options({{"signal_fraction", "--signal"}}, [&] {
    c = compare_images(a, b, has_a ? &var_a : nullptr, has_b ? &var_b : nullptr, o.signal, o.a, o.b);
  });
  std::vector<double> ranges;
  if (!o.diff.empty()) {
    ImageMetadata meta;
    meta.units = "false colour of A - B";
    write_image(difference_picture(a, b, o.signal, &ranges), o.diff, meta, o.force);
  }
  if (o.json) {
    std::printf("%s\n", to_json(c).c_str());
    return;
  }
  std::printf("%s against %s%s%s; pixels with signal: reference above %g of its peak\n", o.a.c_str(), o.b.c_str(),
              has_b ? " (variance " : "", has_b ? (vb + ")").c_str() : "", o.signal);
  std::printf("%-5s %8s %10s %10s %10s %20s %10s %10s %8s %s\n", "band", "pixels", "rel L1", "rel L2", "worst 1%",
              "bias +- stderr", "noise L2", "excess L2", "mean z2", "within noise");
  for (const BandComparison& r : c.bands)
    std::printf("%-5s %8zu %10.4g %10.4g %10.4g %+10.4g +- %-6.2g %10.4g %10.4g %8.3g %s\n", r.band.c_str(),
                r.signal_pixels, r.rel_l1, r.rel_l2, r.worst_1pct, r.bias, r.bias_stderr, r.noise_rel_l2,
                r.rel_l2_excess, r.mean_z2, r.has_variance ? (r.within_noise ? "yes" : "no") : "(no variance image)");
  if (!o.diff.empty()) {
    std::printf("wrote %s: white equal, red A brighter, blue A darker; full colour at", o.diff.c_str());
    for (size_t k = 0; k < ranges.size(); ++k) std::printf(" %s +-%.3g", c.bands[k].band.c_str(), ranges[k]);
    std::printf("\n");
  }
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("compare", "image A against reference B: relative L1/L2, worst 1%, bias, noise");
  auto o = std::make_shared<Options>();
  cmd->add_option("A", o->a, "image to judge (.h5 .fits .exr)")->required();
  cmd->add_option("B", o->b, "reference image; its variance B.var.EXT is used when present")->required();
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->add_option("--diff", o->diff, "write a false-colour difference picture (.png)");
  cmd->add_option("--signal", o->signal, "pixels with signal: reference above this fraction of its band's peak")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "overwrite an existing --diff picture");
  cmd->callback([o] { run_compare(*o); });
}

}  // namespace nebula::app
