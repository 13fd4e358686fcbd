#pragma once
#include <cstdint>
#include <string>

namespace nebula::app {

// Refuses, before any work starts, an output that exists (unless overwrite),
// lives in a missing or unwritable folder, or is a folder. Throws Error
// naming the option and the path.
void check_output_path(const std::string& option, const std::string& path, bool overwrite);

// 1e6-style numbers for photon counts: a whole number in [lo, hi].
uint64_t parse_count(const std::string& option, const std::string& text, double lo, double hi);

}  // namespace nebula::app
