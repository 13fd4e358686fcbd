#include "pipeline/table_source.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/progress.h"
#include "montecarlo/table_conversion.h"
#include "tables/table_file.h"

namespace nebula {

const char* to_string(TableOrigin origin) {
  switch (origin) {
    case TableOrigin::File: return "read";
    case TableOrigin::Cache: return "cache";
    default: return "generated";
  }
}

std::string table_cache_dir() {
  if (const char* dir = std::getenv("NEBULA_CACHE_DIR"); dir && *dir) return std::string(dir) + "/tables";
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/nebula/tables";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/nebula/tables";
  return ".nebula-cache/tables";
}

ScatteringTable cached_table(const TabulateParams& p, Backend backend, bool progress, TableOrigin* origin,
                             std::string* path_out) {
  validate(p);
  std::ostringstream name;
  name << "hg_a" << p.albedo << "_g" << p.g << "_tau" << p.tau_max << "x" << p.tau_bins << "_"
       << to_string(p.binning) << p.mu_bins << "_" << to_string(p.beam) << "_n" << p.photons_per_row
       << "_s" << p.seed << ".h5";
  const std::filesystem::path dir = table_cache_dir();
  const std::filesystem::path path = dir / name.str();
  if (path_out) *path_out = path.string();
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    if (origin) *origin = TableOrigin::Cache;
    return read_table(path.string());
  }
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("table cache: cannot create " + dir.string() + ": " + ec.message());
  std::unique_ptr<Progress> bar;
  if (progress)
    bar = std::make_unique<Progress>("table a=" + std::to_string(p.albedo).substr(0, 4) +
                                         " g=" + std::to_string(p.g).substr(0, 5),
                                     p.photons_per_row * p.tau_bins);
  const ScatteringTable table = to_table(tabulate(p, backend, bar.get()));
  if (bar) bar->finish();
  write_table(table, path.string(), true);
  if (origin) *origin = TableOrigin::Generated;
  return table;
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

BandTables resolve_tables(const Scene& scene, const TableOptions& options) {
  const size_t n_bands = scene.bands.size();
  BandTables out;
  out.per_band.assign(n_bands, nullptr);
  std::map<std::string, size_t> by_file;                     // file -> report entry
  std::map<std::pair<double, double>, size_t> by_parameters;  // generated or cached (albedo, g) -> report entry
  std::vector<std::shared_ptr<const ScatteringTable>> tables;
  for (size_t b = 0; b < n_bands; ++b) {
    const double a = scene.dust.albedo[b], g = scene.dust.g[b];
    if (a == 0) continue;
    const std::string file = b < scene.dust.table_files.size() ? scene.dust.table_files[b] : "";
    size_t entry = 0;
    if (!file.empty()) {
      auto found = by_file.find(file);
      if (found == by_file.end()) {
        const auto t0 = std::chrono::steady_clock::now();
        try {
          tables.push_back(std::make_shared<const ScatteringTable>(read_table(file)));
        } catch (const Error& e) {
          throw Error(scene.path + ": dust.tables." + scene.bands[b] + ": " + e.what());
        }
        out.report.push_back({tables.back()->albedo, tables.back()->g, {}, TableOrigin::File, file, seconds_since(t0)});
        found = by_file.emplace(file, out.report.size() - 1).first;
      }
      entry = found->second;
      const ScatteringTable& t = *tables[entry];
      if (std::fabs(t.albedo - a) > 1e-9 || std::fabs(t.g - g) > 1e-9)
        throw Error(scene.path + ": dust.tables." + scene.bands[b] + ": " + file + " holds albedo " +
                    to_text(t.albedo) + ", g " + to_text(t.g) + " but band " + scene.bands[b] + " has albedo " +
                    to_text(a) + ", g " + to_text(g) + " (set dust.albedo." + scene.bands[b] + " and dust.g." +
                    scene.bands[b] + " to the table's, or name a table made for them)");
    } else {
      auto found = by_parameters.find({a, g});
      if (found == by_parameters.end()) {
        TabulateParams p;
        p.albedo = a;
        p.g = g;
        p.binning = AngularBinning::UniformTheta;  // better for forward-peaked dust (docs/tabulator.md)
        p.photons_per_row = options.photons_per_row;
        const auto t0 = std::chrono::steady_clock::now();
        TableReport r{a, g, {}, TableOrigin::Cache, "", 0};
        tables.push_back(
            std::make_shared<const ScatteringTable>(cached_table(p, options.backend, options.progress, &r.origin, &r.path)));
        r.seconds = seconds_since(t0);
        out.report.push_back(r);
        found = by_parameters.emplace(std::make_pair(a, g), out.report.size() - 1).first;
      }
      entry = found->second;
    }
    out.per_band[b] = tables[entry];
    out.report[entry].bands.push_back(scene.bands[b]);
  }
  return out;
}

}  // namespace nebula
