#pragma once
// The filters bands are named by (DESIGN.md section 3, "Bands"): a name, the
// data file holding its transmission curve and where the numbers come from.
// A scene's `bands` are filter names; the renderers know a band only by its
// name and the physics computed from its passband (extinction ratio, star
// band powers), so a new filter is a new entry here and a file in data/.
#include <string>
#include <vector>

#include "illumination/passband.h"

namespace nebula {

struct FilterInfo {
  std::string name;    // as scenes write it, e.g. "V"
  std::string file;    // under <data_dir>/filters/
  std::string source;  // the publication of the curve
};

// Every filter with a curve in data/filters.
const std::vector<FilterInfo>& known_filters();

// The filters a scene may render today: those whose whole passband lies in
// the range of the extinction law (illumination/extinction.h): B, V and R.
// (U reaches 300 nm, beyond the law's optical part; I is in range but waits
// for the spectral system with the rest of the filters.)
const std::vector<std::string>& renderable_filters();
bool is_renderable_filter(const std::string& name);

// The passband of a known filter, from `data_dir` (default_data_dir() when
// empty). Error naming the filter and the known ones otherwise.
Passband load_filter(const std::string& name, const std::string& data_dir = "");

}  // namespace nebula
