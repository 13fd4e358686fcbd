#pragma once
#include <string>

#include "tables/scattering_table.h"

namespace nebula {

// The HDF5 scattering-table file of DESIGN.md section 4. Both functions throw
// Error with one line naming the file, the field and the expectation. The
// HDF5 library is not thread-safe: calls here are serialised by a mutex, but
// other HDF5 users in the same process must not run concurrently.

// Checks the table, writes it to PATH.tmp-PID beside the target and renames
// it into place, so readers never see a partial file; on failure nothing is
// left behind. An existing PATH is refused unless `overwrite`.
void write_table(const ScatteringTable& table, const std::string& path, bool overwrite);

// Reads and checks a table file; refuses missing, foreign, malformed or
// inconsistent files.
ScatteringTable read_table(const std::string& path);
// A table this program wrote itself (the table cache, written aside and
// renamed): read in the process, without read_table's child first. A child
// forked from a process holding a GPU context and large bakes costs tens of
// milliseconds, once per table of a sweep.
ScatteringTable read_own_table(const std::string& path);

}  // namespace nebula
