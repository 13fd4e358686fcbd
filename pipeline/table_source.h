#pragma once
// Scattering tables for rendering (DESIGN.md section 3, "Table"): per scene
// band, the file the scene names for that band, or a table generated on first
// use and cached by its parameters.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/backend.h"
#include "montecarlo/tabulate.h"
#include "pipeline/run_report.h"
#include "scene/scene.h"
#include "tables/scattering_table.h"

namespace nebula {

// Where generated tables live: $NEBULA_CACHE_DIR/tables, else
// $XDG_CACHE_HOME/nebula/tables, else ~/.cache/nebula/tables, else
// ./.nebula-cache/tables.
std::string table_cache_dir();

// The cache entry's file name: every parameter written exactly (the shortest
// text that reads back as the same double), so different requests never share one.
std::string table_cache_name(const TabulateParams& p);

// The cached table for these parameters, generating (and caching) it when
// absent. An entry that cannot be read, or holds another table than the one
// asked for, is generated again and `warning` (may be null) says so. When the
// cache folder cannot be written, fails before the Monte-Carlo work with an
// Error naming the folder. `origin` and `path` (may be null) receive where the
// table came from.
ScatteringTable cached_table(const TabulateParams& p, Backend backend, bool progress, TableOrigin* origin,
                             std::string* path, std::string* warning = nullptr);

struct TableOptions {
  Backend backend = Backend::Cpu;
  uint64_t photons_per_row = 30000;  // for tables generated on first use
  bool progress = false;             // a progress bar while generating
};

struct BandTables {
  std::vector<std::shared_ptr<const ScatteringTable>> per_band;  // null where the band does not scatter
  std::vector<TableReport> report;                               // one per distinct table
};

// One table per band with albedo > 0: the band's own dust.tables file when the
// scene names one (read once per file, and refused unless its albedo and g
// are the band's, naming the key), else the cached or generated table for the
// band's (albedo, g) with the uniform-theta binning, one shared by all such
// bands with that pair. A file serves only the bands that name it.
BandTables resolve_tables(const Scene& scene, const TableOptions& options);

}  // namespace nebula
