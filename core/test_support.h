#pragma once
// Test-only helpers shared by the folders' GoogleTest binaries (header-only;
// GoogleTest comes from the test target, not from nebula_core).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/gpu.h"

// Skips the current test, saying why, where no CUDA device can run our kernels
// (CI, the development machine); GPU tests carry the ctest label "gpu" and run
// on a machine with one. A statement: NEBULA_SKIP_WITHOUT_GPU();
#define NEBULA_SKIP_WITHOUT_GPU()                                \
  do {                                                           \
    std::string nebula_no_gpu_reason;                            \
    if (!::nebula::gpu_available(&nebula_no_gpu_reason))         \
      GTEST_SKIP() << "no usable GPU: " << nebula_no_gpu_reason; \
  } while (0)

namespace nebula::testing {

// Calls `action`, which must throw Error with one line containing every piece.
template <class Action>
void expect_error(Action action, const std::vector<std::string>& pieces) {
  try {
    action();
    ADD_FAILURE() << "no error; expected one mentioning " << pieces.front();
  } catch (const Error& e) {
    const std::string message = e.what();
    for (const std::string& piece : pieces)
      EXPECT_NE(message.find(piece), std::string::npos) << "missing '" << piece << "' in: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// Sets an environment variable for its lifetime and puts back what was
// there (or unsets it) afterwards, so that one test's setting never leaks
// into the next test of the same binary.
class ScopedEnv {
 public:
  ScopedEnv(std::string name, const std::string& value) : name_(std::move(name)) {
    const char* old = std::getenv(name_.c_str());
    had_ = old != nullptr;
    if (had_) saved_ = old;
    setenv(name_.c_str(), value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_)
      setenv(name_.c_str(), saved_.c_str(), 1);
    else
      unsetenv(name_.c_str());
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_, saved_;
  bool had_ = false;
};

// A fresh folder PREFIX_PID_SUITE_TEST for the running test, removed again
// afterwards (read-only ones too). The pid keeps parallel ctest runs and
// death-test children apart. Tests fixtures derive from it.
struct ScratchDir {
  explicit ScratchDir(const std::string& prefix) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (prefix + "_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" +
            info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::permissions(dir_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ignored);
    std::filesystem::remove_all(dir_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // The names in the folder, sorted.
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir_))
      names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  std::filesystem::path dir_;
};

}  // namespace nebula::testing
