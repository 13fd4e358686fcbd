#pragma once
// User curves as plain two-column text: "wavelength_nm value" per line,
// separated by spaces, tabs or a comma; '#' starts a comment. A user filter
// (a scene's [filters] table, `nebula filters --file`) may also be a CSV
// passband with the header of data/filters/README.md. Star spectra use the
// same reader (spectral/spectra.h).
#include <string>
#include <vector>

#include "illumination/passband.h"

namespace nebula {

struct TwoColumns {
  std::vector<double> x, y;
};
// Refuses, with "<path>:<line>: <reason>": a missing file, a line without two
// numbers, non-finite numbers, a wavelength that is not positive, wavelengths
// not strictly ascending, a negative value, fewer than 2 rows, all zero.
TwoColumns read_two_columns(const std::string& path);

// A user filter: a data/filters CSV (with its header) or two columns in nm.
Passband load_filter_file(const std::string& path);

}  // namespace nebula
