#include "app/table_cache.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>

#include "validation/table_conversion.h"
#include "core/error.h"
#include "core/progress.h"
#include "tables/table_file.h"

namespace nebula::app {

std::string table_cache_dir() {
  if (const char* dir = std::getenv("NEBULA_CACHE_DIR"); dir && *dir) return std::string(dir) + "/tables";
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/nebula/tables";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/nebula/tables";
  return ".nebula-cache/tables";
}

ScatteringTable cached_table(const TabulateParams& p, Backend backend, bool quiet, std::string* origin) {
  validate(p);
  std::ostringstream name;
  name << "hg_a" << p.albedo << "_g" << p.g << "_tau" << p.tau_max << "x" << p.tau_bins << "_"
       << to_string(p.binning) << p.mu_bins << "_" << to_string(p.beam) << "_n" << p.photons_per_row
       << "_s" << p.seed << ".h5";
  const std::filesystem::path dir = table_cache_dir();
  const std::filesystem::path path = dir / name.str();
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    if (origin) *origin = "cache";
    return read_table(path.string());
  }
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("table cache: cannot create " + dir.string() + ": " + ec.message());
  std::unique_ptr<Progress> progress;
  if (!quiet) progress = std::make_unique<Progress>("table a=" + std::to_string(p.albedo).substr(0, 4) +
                                                        " g=" + std::to_string(p.g).substr(0, 5),
                                                    p.photons_per_row * p.tau_bins);
  const ScatteringTable table = to_table(tabulate(p, backend, progress.get()));
  if (progress) progress->finish();
  write_table(table, path.string(), true);
  if (origin) *origin = "generated";
  return table;
}

}  // namespace nebula::app
