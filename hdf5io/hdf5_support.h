#pragma once
// What every HDF5 reader and writer here needs: an owning identifier, the
// error stack's reason in one line, and one lock for the whole program.
#include <hdf5.h>

#include <functional>
#include <mutex>
#include <string>

namespace nebula::hdf5io {

// Owns an HDF5 identifier and closes it with the matching function.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() { close(); }
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) {
    other.id_ = H5I_INVALID_HID;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  bool valid() const { return id_ >= 0; }
  hid_t get() const { return id_; }
  // Closes now and says whether it worked (a file close writes it out).
  bool close() {
    if (id_ < 0) return true;
    const herr_t status = closer_(id_);
    id_ = H5I_INVALID_HID;
    return status >= 0;
  }

 private:
  hid_t id_;
  Closer closer_;
};

// The innermost entry of HDF5's error stack on one line: for a failed system
// call just its complaint ("File too large"); "" when the stack is empty.
std::string hdf5_reason();

// WHAT, followed by " (reason)" when the error stack has one.
std::string with_reason(const std::string& what);

// Serial HDF5 (1.10 unless built thread-safe) must not be entered from two
// threads at once; every caller in the program takes this one lock.
std::mutex& hdf5_mutex();

// libhdf5 1.10 crashes on some damaged files (SIGSEGV in H5F__accum_read, heap
// overflows under H5Aexists). Every reader of a user's file first runs `read`
// in a child process (fork): a crash there becomes an Error naming `path`
// ("the HDF5 library crashed reading it"), an Error there is rethrown here,
// and only a read that succeeded in the child is done again in this process.
// Set NEBULA_HDF5_IN_PROCESS=1 to read in this process only (fuzzing,
// debugging). Call without hdf5_mutex() held; `read` takes it as usual.
void read_in_child_first(const std::string& path, const std::function<void()>& read);

// HDF5 prints its error stack to stderr by default; we report one line
// instead. Call with hdf5_mutex() held.
void silence_hdf5_errors();

}  // namespace nebula::hdf5io
