#include "app/output_path.h"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>

#include "core/error.h"

namespace nebula::app {

void check_output_path(const std::string& option, const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  if (path.empty()) throw Error(option + ": an output file is required");
  const fs::path p(path);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw Error(option + ": " + path + " is a folder, not a file");
  if (fs::exists(p, ec) && !overwrite)
    throw Error(option + ": " + path + " exists; pass --force to overwrite it");
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw Error(option + ": folder " + dir.string() + " does not exist");
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(option + ": cannot write into folder " + dir.string() + " (permission denied)");
}

uint64_t parse_count(const std::string& option, const std::string& text, double lo, double hi) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (...) {
    used = 0;
  }
  if (used != text.size() || text.empty())
    throw Error(option + ": expected a number such as 1e6, got '" + text + "'");
  if (!(v >= lo && v <= hi) || v != std::floor(v))
    throw Error(option + ": expected a whole number from " + std::to_string(uint64_t(lo)) + " to " +
                std::to_string(uint64_t(hi)) + ", got '" + text + "'");
  return static_cast<uint64_t>(v);
}

}  // namespace nebula::app
