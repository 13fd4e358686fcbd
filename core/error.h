#pragma once
#include <cstdio>
#include <stdexcept>
#include <string>

namespace nebula {

// Every user-facing failure: a single line naming the file, key or option and
// the reason. The command line prints what() and exits non-zero.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A number as error messages and summaries print it (%.6g).
inline std::string to_text(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace nebula
