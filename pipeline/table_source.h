#pragma once
// Scattering tables for rendering: read from a named file, or generated on
// first use and cached by their parameters.
#include <string>

#include "core/backend.h"
#include "montecarlo/tabulate.h"
#include "tables/scattering_table.h"

namespace nebula::app {

// Where generated tables live: $NEBULA_CACHE_DIR, else $XDG_CACHE_HOME/nebula,
// else ~/.cache/nebula, else ./.nebula-cache.
std::string table_cache_dir();

// The cached table for these parameters, generating it (and saying so on
// stdout) when absent. `origin` receives "cache" or "generated".
ScatteringTable cached_table(const TabulateParams& p, Backend backend, bool quiet, std::string* origin);

}  // namespace nebula::app
