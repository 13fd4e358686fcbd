#include "pipeline/table_source.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <list>
#include <map>
#include <mutex>
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

namespace {

// The shortest text that reads back as exactly `v` (std::to_chars): two
// different parameters never share a cache entry, and 0.6 stays "0.6".
std::string exact_text(double v) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof text, v);
  return std::string(text, result.ptr);
}

// Why a table read from the cache is not the one asked for, or "".
std::string mismatch(const ScatteringTable& t, const TabulateParams& p) {
  const ScatteringTable axes = ScatteringTable::make_axes(p.tau_max, p.tau_bins, p.binning, p.mu_bins);
  auto differs = [](const std::string& field, const std::string& have, const std::string& want) {
    return field + " is " + have + ", not " + want;
  };
  if (t.albedo != p.albedo) return differs("albedo", exact_text(t.albedo), exact_text(p.albedo));
  if (t.g != p.g) return differs("g", exact_text(t.g), exact_text(p.g));
  if (t.tau != axes.tau)
    return "the tau axis (" + std::to_string(t.tau.size()) + " rows to " +
           (t.tau.empty() ? std::string("-") : exact_text(t.tau.back())) + ") is not " +
           std::to_string(p.tau_bins) + " rows to " + exact_text(p.tau_max);
  if (t.mu_binning != p.binning || t.mu_edges != axes.mu_edges)
    return "the mu bins are not " + std::to_string(p.mu_bins) + " " + to_string(p.binning) + " bins";
  if (t.illumination != to_string(p.beam)) return differs("illumination", t.illumination, to_string(p.beam));
  if (t.photons_per_row != p.photons_per_row)
    return differs("photons_per_row", std::to_string(t.photons_per_row), std::to_string(p.photons_per_row));
  if (t.thin_boost != uint64_t(p.thin_boost))
    return differs("thin_boost", std::to_string(t.thin_boost), std::to_string(p.thin_boost));
  if (t.seed != p.seed) return differs("seed", std::to_string(t.seed), std::to_string(p.seed));
  if (t.forced_first_scattering != p.forced_first_scattering || t.roulette_threshold != p.roulette.threshold ||
      t.roulette_survival != p.roulette.survival || t.max_orders != p.roulette.max_orders)
    return "the transport settings (forced first scattering, roulette, order limit) differ";
  return "";
}

// Cache entries this process has read and checked, by path, with the file's
// size and modification time then: a sweep or a Python loop asks for the same
// few tables again and again (3-4 ms a read of HDF5), and an entry that
// changed on disk since is read and checked again. The most recent kMemoEntries.
class CheckedEntries {
 public:
  static constexpr size_t kMemoEntries = 64;
  // The file as stat(2) sees it: a rewrite (the cache writes aside and renames,
  // so a new inode) or any change of size or times makes another stamp.
  struct Stamp {
    dev_t device = 0;
    ino_t inode = 0;
    off_t size = 0;
    long long mtime_ns = 0, ctime_ns = 0;
    bool operator==(const Stamp& o) const {
      return device == o.device && inode == o.inode && size == o.size && mtime_ns == o.mtime_ns &&
             ctime_ns == o.ctime_ns;
    }
  };
  static bool stamp_of(const std::filesystem::path& path, Stamp& out) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return false;
    out.device = st.st_dev;
    out.inode = st.st_ino;
    out.size = st.st_size;
    out.mtime_ns = (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec;
    out.ctime_ns = (long long)st.st_ctim.tv_sec * 1000000000LL + st.st_ctim.tv_nsec;
    return true;
  }
  std::shared_ptr<const ScatteringTable> find(const std::string& path, const Stamp& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = entries_.begin(); it != entries_.end(); ++it)
      if (it->path == path) {
        if (!(it->stamp == stamp)) {
          entries_.erase(it);
          return nullptr;
        }
        entries_.splice(entries_.begin(), entries_, it);  // most recent first
        return entries_.front().table;
      }
    return nullptr;
  }
  void add(const std::string& path, const Stamp& stamp, std::shared_ptr<const ScatteringTable> table) {
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.remove_if([&](const Entry& e) { return e.path == path; });
    entries_.push_front({path, stamp, std::move(table)});
    if (entries_.size() > kMemoEntries) entries_.pop_back();
  }

 private:
  struct Entry {
    std::string path;
    Stamp stamp;
    std::shared_ptr<const ScatteringTable> table;
  };
  std::mutex mutex_;
  std::list<Entry> entries_;
};

CheckedEntries& checked_entries() {
  static CheckedEntries memo;
  return memo;
}

}  // namespace

std::string table_cache_name(const TabulateParams& p) {
  return "hg_a" + exact_text(p.albedo) + "_g" + exact_text(p.g) + "_tau" + exact_text(p.tau_max) + "x" +
         std::to_string(p.tau_bins) + "_" + to_string(p.binning) + std::to_string(p.mu_bins) + "_" +
         to_string(p.beam) + "_n" + std::to_string(p.photons_per_row) + "_b" + std::to_string(p.thin_boost) + "_s" +
         std::to_string(p.seed) + ".h5";
}

ScatteringTable cached_table(const TabulateParams& p, Backend backend, bool progress, TableOrigin* origin,
                             std::string* path_out, std::string* warning) {
  validate(p);
  const std::filesystem::path dir = table_cache_dir();
  const std::filesystem::path path = dir / table_cache_name(p);
  if (path_out) *path_out = path.string();
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    // An entry is trusted only once read, checked and found to be the table
    // asked for (the path holds every parameter, so once per unchanged file).
    CheckedEntries::Stamp stamp;
    const bool stamped = CheckedEntries::stamp_of(path, stamp);
    if (stamped)
      if (std::shared_ptr<const ScatteringTable> known = checked_entries().find(path.string(), stamp)) {
        if (origin) *origin = TableOrigin::Cache;
        return *known;
      }
    std::string problem;
    try {
      ScatteringTable cached = read_own_table(path.string());
      problem = mismatch(cached, p);
      if (problem.empty()) {
        if (origin) *origin = TableOrigin::Cache;
        if (stamped) checked_entries().add(path.string(), stamp, std::make_shared<const ScatteringTable>(cached));
        return cached;
      }
    } catch (const Error& e) {
      problem = e.what();
    }
    if (warning)
      *warning = "table cache: the entry " + path.string() + " is unusable (" + problem + "); generated it again";
  }
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("table cache: cannot create " + dir.string() + ": " + ec.message());
  // Fail before the Monte-Carlo work, not after it, when the entry cannot be written.
  {
    const std::string probe = (dir / (".write-probe-" + std::to_string(::getpid()))).string();
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0)
      throw Error("table cache: cannot write into " + dir.string() + " (" + std::strerror(errno) +
                  "); set NEBULA_CACHE_DIR to a writable folder");
    ::close(fd);
    ::unlink(probe.c_str());
  }
  std::unique_ptr<Progress> bar;
  if (progress)
    bar = std::make_unique<Progress>("table a=" + std::to_string(p.albedo).substr(0, 4) +
                                         " g=" + std::to_string(p.g).substr(0, 5),
                                     photons_of_table(p));
  const ScatteringTable table = to_table(tabulate(p, backend, bar.get()));
  if (bar) bar->finish();
  try {
    write_table(table, path.string(), true);
  } catch (const Error& e) {
    throw Error(std::string("table cache: ") + e.what());
  }
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
        out.report.push_back({tables.back()->albedo, tables.back()->g, {}, TableOrigin::File, file, seconds_since(t0), ""});
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
        TableReport r{a, g, {}, TableOrigin::Cache, "", 0, ""};
        tables.push_back(std::make_shared<const ScatteringTable>(
            cached_table(p, options.backend, options.progress, &r.origin, &r.path, &r.warning)));
        r.seconds = seconds_since(t0);
        out.report.push_back(r);
        found = by_parameters.emplace(std::make_pair(a, g), out.report.size() - 1).first;
      }
      entry = found->second;
    }
    out.per_band[b] = tables[entry];
    if (out.report[entry].bands.empty()) {
      out.report[entry].noise = tables[entry]->median_relative_error();
      out.report[entry].photons_per_row = tables[entry]->photons_per_row;
    }
    out.report[entry].bands.push_back(scene.bands[b]);
  }
  return out;
}

}  // namespace nebula
