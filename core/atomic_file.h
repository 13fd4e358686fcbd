#pragma once
// Writing a file so that no half-written one is ever seen: write to a
// temporary beside the target, fsync it, rename it into place. Shared by
// tables/ and imageio/; standard library and POSIX only.
#include <string>

namespace nebula {

// Refuses, with Error("cannot write PATH: ..."), before anything is created:
// a target that is a folder, an existing file unless `overwrite`, and with
// `check_folder` a missing or non-folder parent. `folder_word` names a folder
// in the message: tables say "directory", imageio "folder", and tests check both.
void check_output_target(const std::string& path, bool overwrite, const char* folder_word,
                         bool check_folder);

// Makes a finished file durable before a rename publishes it; errno's text
// on failure, "" on success.
std::string sync_file(const std::string& path);

// An empty file TARGET.tmp-PID-N beside the target, removed again unless
// published. We create it ourselves so an unwritable folder fails with
// errno's plain reason ("Permission denied") rather than a format library's.
// SIGINT, SIGTERM and SIGHUP remove every live temporary before the process
// dies of the signal (the handlers are installed on the first temporary, only
// where the signal has its default disposition); and creating one removes the
// stale TARGET.tmp-PID-N of the same target left by processes that no longer
// exist.
class TemporaryFile {
 public:
  // Throws Error("cannot write TARGET: <errno text>") when it cannot be created.
  explicit TemporaryFile(const std::string& target);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  const std::string& path() const { return path_; }
  // fsyncs the temporary and renames it over the target; throws Error
  // naming the target on failure (the destructor then removes the temporary).
  void publish();

 private:
  std::string target_;
  std::string path_;
  bool published_ = false;
  int slot_ = -1;  // in the signal handler's table, or -1
};

}  // namespace nebula
