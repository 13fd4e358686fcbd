#pragma once
#include <stdexcept>
#include <string>

namespace nebula {

// Every user-facing failure: a single line naming the file, key or option and
// the reason. The command line prints what() and exits non-zero.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace nebula
