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
    return out;
  }();
  return filters;
}

const std::vector<std::string>& renderable_filters() {
  static const std::vector<std::string> names{"B", "V", "R"};
  return names;
}

bool is_renderable_filter(const std::string& name) {
  const std::vector<std::string>& names = renderable_filters();
  return std::find(names.begin(), names.end(), name) != names.end();
}

Passband load_filter(const std::string& name, const std::string& data_dir) {
  std::string known;
  for (const FilterInfo& f : known_filters()) {
    if (f.name == name) return load_passband((data_dir.empty() ? default_data_dir() : data_dir) + "/filters/" + f.file);
    known += (known.empty() ? "" : ", ") + f.name;
  }
  throw Error("filter '" + name + "' is not known (known: " + known + ")");
}

}  // namespace nebula
