#pragma once
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

namespace nebula {

// Every user-facing failure: a single line naming the file, key or option and
// the reason. The command line prints what() and exits non-zero.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A bad value of one named parameter of a library call. `parameter` is the
// name the library gives it (a struct field such as "albedo", or a scene key
// such as "render.levels"); what() is "<parameter>: <reason>". Library code
// never names a command-line option: a front end that took the value from one
// rewords the error with its option's name (app/cli_support.h).
class ParameterError : public Error {
 public:
  ParameterError(std::string parameter, std::string reason)
      : Error(parameter + ": " + reason), parameter_(std::move(parameter)), reason_(std::move(reason)) {}
  const std::string& parameter() const { return parameter_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string parameter_, reason_;
};

// A number as error messages and summaries print it (%.6g).
inline std::string to_text(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace nebula
