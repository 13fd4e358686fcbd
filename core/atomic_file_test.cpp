#include "core/atomic_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

#include "core/test_support.h"

namespace nebula {
namespace {

class AtomicFile : public ::testing::Test, protected testing::ScratchDir {
 protected:
  AtomicFile() : ScratchDir("nebula_atomic") {}

  // A child that starts writing `target` through a temporary, then receives
  // `sig` from itself before publishing; returns its wait status.
  int die_while_writing(const std::string& target, int sig) {
    const pid_t child = ::fork();
    if (child == 0) {
      TemporaryFile temporary(target);
      std::ofstream(temporary.path()) << "half an image";
      ::kill(::getpid(), sig);
      ::_exit(0);  // not reached when the signal kills
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    return status;
  }
};

// Issue 17, item 5: SIGINT or SIGTERM while an image is written left
// NAME.tmp-PID-0 behind.
TEST_F(AtomicFile, SignalsRemoveTheTemporary) {
  for (int sig : {SIGTERM, SIGINT}) {
    const std::string target = path("image.fits");
    const int status = die_while_writing(target, sig);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child was not killed by signal " << sig;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_EQ(files(), std::vector<std::string>{}) << "signal " << sig;
  }
}

// Issue 17, item 5: a later run removes the temporaries of its own target that
// dead processes left, and nothing else.
TEST_F(AtomicFile, LaterRunsRemoveStaleTemporaries) {
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);  // reaped: that pid is no process now
  const std::string stale = "out.h5.tmp-" + std::to_string(dead) + "-0";
  const std::string alive = "out.h5.tmp-" + std::to_string(::getppid()) + "-3";
  const std::string other = "other.h5.tmp-" + std::to_string(dead) + "-0";
  for (const std::string& name : {stale, alive, other}) std::ofstream(path(name)) << "x";
  {
    TemporaryFile temporary(path("out.h5"));
    std::ofstream(temporary.path()) << "new";
    temporary.publish();
  }
  std::vector<std::string> want{"other.h5.tmp-" + std::to_string(dead) + "-0", "out.h5", alive};
  std::sort(want.begin(), want.end());
  EXPECT_EQ(files(), want);
}

}  // namespace
}  // namespace nebula
