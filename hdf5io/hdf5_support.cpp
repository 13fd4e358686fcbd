#include "hdf5io/hdf5_support.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "core/error.h"

namespace nebula::hdf5io {

std::string hdf5_reason() {
  std::string reason;
  auto take_first = [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
    if (n == 0 && e->desc != nullptr) *static_cast<std::string*>(out) = e->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, take_first, &reason);
  const std::string marker = "error message = '";
  const size_t at = reason.find(marker);
  if (at != std::string::npos) {
    const size_t begin = at + marker.size();
    reason = reason.substr(begin, reason.find('\'', begin) - begin);
  }
  std::replace(reason.begin(), reason.end(), '\n', ' ');
  return reason;
}

std::string with_reason(const std::string& what) {
  const std::string reason = hdf5_reason();
  return reason.empty() ? what : what + " (" + reason + ")";
}

namespace {

// True in a child of read_in_child_first: it has its own HDF5 lock (the
// parent's was held across the fork) and forks no further.
bool g_in_child = false;

constexpr int kChildError = 42;  // the child's read threw; its message is on the pipe

}  // namespace

std::mutex& hdf5_mutex() {
  static std::mutex m;
  static std::mutex child;
  return g_in_child ? child : m;
}

void read_in_child_first(const std::string& path, const std::function<void()>& read) {
  if (g_in_child) return read();
  if (const char* v = std::getenv("NEBULA_HDF5_IN_PROCESS"); v && std::strcmp(v, "1") == 0) return;
  int fds[2];
  if (::pipe(fds) != 0) throw Error(path + ": cannot read it safely: pipe failed (" + std::strerror(errno) + ")");
  pid_t child = -1;
  {
    // No other thread is inside HDF5 while the child's copy of it is made.
    const std::lock_guard<std::mutex> lock(hdf5_mutex());
    child = ::fork();
  }
  if (child < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(path + ": cannot read it safely: fork failed (" + std::strerror(err) + ")");
  }
  if (child == 0) {
    ::close(fds[0]);
    g_in_child = true;
    std::string message;
    try {
      read();
      ::_exit(0);
    } catch (const std::exception& e) {
      message = e.what();
    } catch (...) {
      message = path + ": unknown error while reading";
    }
    for (size_t done = 0; done < message.size();) {
      const ssize_t n = ::write(fds[1], message.data() + done, message.size() - done);
      if (n <= 0) break;
      done += size_t(n);
    }
    ::_exit(kChildError);
  }
  ::close(fds[1]);
  std::string message;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n > 0) {
      message.append(buffer, size_t(n));
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      break;
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kChildError) throw Error(message);
  if (WIFSIGNALED(status))
    throw Error(path + ": the HDF5 library crashed reading it (" + strsignal(WTERMSIG(status)) +
                "): the file is damaged or not what it claims to be");
  // Any other exit is a crash too: under a sanitizer (or a library that
  // calls exit), a fault ends the child with a status instead of a signal.
  throw Error(path + ": the HDF5 library crashed reading it (exit status " + std::to_string(WEXITSTATUS(status)) +
              "): the file is damaged or not what it claims to be");
}

void silence_hdf5_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

}  // namespace nebula::hdf5io
