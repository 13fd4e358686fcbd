#include "core/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "core/error.h"

namespace nebula {

namespace fs = std::filesystem;

namespace {

// The temporaries being written now, for the SIGINT/SIGTERM handler: fixed
// slots (a handler may not allocate or lock), each a path and a flag saying
// it is live. A slot's path is written before its flag is set and is not
// touched again until the flag is cleared.
constexpr int kSlots = 64;
constexpr size_t kPathBytes = 4096;
char g_paths[kSlots][kPathBytes];
std::atomic<bool> g_claimed[kSlots];  // owned by a TemporaryFile
std::atomic<bool> g_live[kSlots];     // its path is complete and the file may exist
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void remove_temporaries_and_die(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_live[i].load()) ::unlink(g_paths[i]);
  // Die of the same signal, as the default disposition would have.
  struct sigaction plain {};
  plain.sa_handler = SIG_DFL;
  sigemptyset(&plain.sa_mask);
  ::sigaction(sig, &plain, nullptr);
  ::raise(sig);
}

// Installed on the first temporary, only over the default disposition: a
// program that ignores or handles these signals itself keeps its choice.
void install_signal_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : kSignals) {
      struct sigaction previous {};
      if (::sigaction(sig, nullptr, &previous) != 0 || previous.sa_handler != SIG_DFL) continue;
      struct sigaction handler {};
      handler.sa_handler = remove_temporaries_and_die;
      sigemptyset(&handler.sa_mask);
      ::sigaction(sig, &handler, nullptr);
    }
  });
}

// A slot for `path`, or -1 when all are taken or the path is too long (the
// file is then only removed by the destructor and by later runs).
int register_temporary(const std::string& path) {
  if (path.size() + 1 > kPathBytes) return -1;
  install_signal_cleanup();
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (!g_claimed[i].compare_exchange_strong(expected, true)) continue;
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    g_live[i].store(true);
    return i;
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot < 0) return;
  g_live[slot].store(false);
  g_claimed[slot].store(false);
}

// Temporaries of `target` (TARGET.tmp-PID-N) left by runs that died: their
// process no longer exists. Removed quietly; anything else is left alone.
void remove_stale_temporaries(const std::string& target) {
  const fs::path t(target);
  const fs::path folder = t.has_parent_path() ? t.parent_path() : fs::path(".");
  const std::string prefix = t.filename().string() + ".tmp-";
  std::error_code ec;
  fs::directory_iterator it(folder, ec);
  if (ec) return;
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());  // PID-N
    const size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || rest.find_first_not_of("0123456789-") != std::string::npos) continue;
    const long pid = std::strtol(rest.substr(0, dash).c_str(), nullptr, 10);
    if (pid <= 0 || pid == long(::getpid())) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code ignored;
    fs::remove(entry.path(), ignored);
  }
}

}  // namespace

void check_output_target(const std::string& path, bool overwrite, const char* folder_word,
                         bool check_folder) {
  const std::string where = "cannot write " + path + ": ";
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) throw Error(where + "it is a " + folder_word);
  if (fs::exists(status) && !overwrite)
    throw Error(where + "the file exists (overwriting was not requested)");
  if (!check_folder) return;
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const fs::file_status folder_status = fs::status(folder, ec);
  if (!fs::exists(folder_status))
    throw Error(where + folder_word + " " + folder.string() + " does not exist");
  if (!fs::is_directory(folder_status))
    throw Error(where + folder.string() + " is not a " + folder_word);
}

std::string sync_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY);
  if (fd < 0) return std::strerror(errno);
  if (::fsync(fd) != 0 && errno != EINVAL) {  // EINVAL: a file system without fsync
    const std::string reason = std::strerror(errno);
    ::close(fd);
    return reason;
  }
  if (::close(fd) != 0) return std::strerror(errno);
  return {};
}

TemporaryFile::TemporaryFile(const std::string& target) : target_(target) {
  // The counter keeps two threads writing the same target apart.
  static std::atomic<unsigned> counter{0};
  path_ = target + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  remove_stale_temporaries(target);
  slot_ = register_temporary(path_);  // before the file exists: a signal now removes nothing, harmlessly
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) {
    const int err = errno;
    unregister_temporary(slot_);
    throw Error("cannot write " + target + ": " + std::strerror(err));
  }
  ::close(fd);
}

TemporaryFile::~TemporaryFile() {
  if (!published_) {
    std::error_code ignored;
    fs::remove(path_, ignored);
  }
  unregister_temporary(slot_);
}

void TemporaryFile::publish() {
  const std::string failure = sync_file(path_);
  if (!failure.empty()) throw Error("cannot write " + target_ + ": " + failure);
  // rename() replaces atomically; the callers' existence check has a small
  // race with other writers, acceptable for files made by one run at a time.
  std::error_code ec;
  fs::rename(path_, target_, ec);
  if (ec)
    throw Error("cannot write " + target_ + ": renaming the temporary file failed: " + ec.message());
  published_ = true;
  unregister_temporary(slot_);  // the name now belongs to the target
  slot_ = -1;
}

}  // namespace nebula
