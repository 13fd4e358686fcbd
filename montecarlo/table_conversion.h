#pragma once
#include "montecarlo/tabulate.h"
#include "tables/scattering_table.h"

namespace nebula {

// The tabulator's result as the table file's type, with its provenance.
ScatteringTable to_table(const Tabulation& t);

}  // namespace nebula
