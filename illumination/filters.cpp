#include "illumination/filters.h"

#include <algorithm>

#include "core/error.h"
#include "illumination/data_dir.h"

namespace nebula {

const std::vector<FilterInfo>& known_filters() {
  static const std::vector<FilterInfo> filters = [] {
    std::vector<FilterInfo> out;
    for (const char* band : {"U", "B", "V", "R", "I"})
      out.push_back({band, std::string("bessell-") + band + ".csv", "Bessell (1990), PASP 102, 1181"});
    // scripts/import_filters.py wrote these; each file's first line gives its source in full.
    for (const char* band : {"u", "g", "r", "i", "z"})
      out.push_back({std::string("sdss_") + band, std::string("sdss-") + band + ".csv",
                     "SDSS, Doi et al. (2010), AJ 139, 1628 (airmass 1.3)"});
    for (const char* f : {"F435W", "F475W", "F555W", "F606W", "F625W", "F775W", "F814W"})
      out.push_back({f, std::string("hst-acs-") + f + ".csv", "HST ACS/WFC throughput (STScI)"});
    for (const char* f : {"F336W", "F475W", "F555W", "F606W", "F814W"})
      out.push_back({std::string("wfc3_") + f, std::string("hst-wfc3-") + f + ".csv",
                     "HST WFC3/UVIS throughput (STScI)"});
    for (const char* f : {"F105W", "F125W", "F160W"})
      out.push_back({std::string("wfc3_") + f, std::string("hst-wfc3-") + f + ".csv",
                     "HST WFC3/IR throughput (STScI)"});
    for (const char* f : {"F070W", "F090W", "F115W", "F150W", "F200W", "F277W", "F356W", "F444W"})
      out.push_back({f, std::string("jwst-nircam-") + f + ".csv", "JWST NIRCam throughput, post-flight 2024 (STScI)"});
    return out;
  }();
  return filters;
}

const std::vector<std::string>& renderable_filters() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const FilterInfo& f : known_filters()) out.push_back(f.name);
    return out;
  }();
  return names;
}

bool is_renderable_filter(const std::string& name) {
  const std::vector<std::string>& names = renderable_filters();
  return std::find(names.begin(), names.end(), name) != names.end();
}

Passband load_filter(const std::string& name, const std::string& data_dir) {
  std::string known;
  for (const FilterInfo& f : known_filters()) {
    if (f.name == name) {
      Passband p = load_passband((data_dir.empty() ? default_data_dir() : data_dir) + "/filters/" + f.file);
      return p;
    }
    known += (known.empty() ? "" : ", ") + f.name;
  }
  throw Error("filter '" + name + "' is not known (known: " + known + ")");
}

}  // namespace nebula
