#include "core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace nebula {

namespace fs = std::filesystem;

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
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) throw Error("cannot write " + target + ": " + std::strerror(errno));
  ::close(fd);
}

TemporaryFile::~TemporaryFile() {
  if (!published_) {
    std::error_code ignored;
    fs::remove(path_, ignored);
  }
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
}

}  // namespace nebula
