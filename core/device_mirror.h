#pragma once
// A device copy kept beside a host array that no longer changes once made (a
// baked diffuse field, say): the CUDA path uploads it once, or its producer
// leaves its own device result there, and every later kernel reads that copy
// instead of uploading the array again. Host code sees only an opaque
// handle, so builds without CUDA carry it for free. Whoever changes the host
// array must reset() its mirror; a copy of the owner starts without one
// (the copy may be changed: it uploads its own), a move takes it along.
// Threads may render from one owner at once (the viewer's window and its
// worker): a mirror is read and filled under one process-wide lock.
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>

namespace nebula {

class DeviceMirror {
 public:
  DeviceMirror() = default;
  DeviceMirror(const DeviceMirror&) {}
  DeviceMirror& operator=(const DeviceMirror&) {
    reset();
    return *this;
  }
  DeviceMirror(DeviceMirror&& other) noexcept {
    std::lock_guard<std::mutex> lock(mutex());
    take(other);
  }
  DeviceMirror& operator=(DeviceMirror&& other) noexcept {
    std::lock_guard<std::mutex> lock(mutex());
    if (this != &other) take(other);
    return *this;
  }

  // The device copy of `bytes` bytes, made by upload() (which returns its
  // owner and device pointer) when the mirror holds none of that size.
  // The owner comes back too, for the caller to keep it alive while it uses it.
  struct Copy {
    std::shared_ptr<const void> owner;
    const void* device = nullptr;
  };
  Copy get_or_upload(size_t bytes, const std::function<Copy()>& upload) {
    std::lock_guard<std::mutex> lock(mutex());
    if (device_ == nullptr || bytes_ != bytes) {
      const Copy made = upload();
      owner_ = made.owner;
      device_ = made.device;
      bytes_ = bytes;
    }
    return {owner_, device_};
  }
  // Holds `copy` (a producer's device result, `bytes` long).
  void set(Copy copy, size_t bytes) {
    std::lock_guard<std::mutex> lock(mutex());
    owner_ = std::move(copy.owner);
    device_ = copy.device;
    bytes_ = bytes;
  }
  // Takes over `same`'s device copy: for an owner copied from another whose
  // array is, and stays, equal to it.
  void share(const DeviceMirror& same) {
    std::lock_guard<std::mutex> lock(mutex());
    owner_ = same.owner_;
    device_ = same.device_;
    bytes_ = same.bytes_;
  }
  // The device copy it holds (none: a null device pointer).
  Copy current() const {
    std::lock_guard<std::mutex> lock(mutex());
    return {owner_, device_};
  }
  bool holds(size_t bytes) const {
    std::lock_guard<std::mutex> lock(mutex());
    return device_ != nullptr && bytes_ == bytes;
  }
  // Copies the device copy's bytes into `host` (CUDA builds; elsewhere, or
  // when the mirror holds no such copy, throws Error).
  void download(void* host, size_t bytes) const;
  void reset() {
    std::lock_guard<std::mutex> lock(mutex());
    owner_.reset();
    device_ = nullptr;
    bytes_ = 0;
  }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  void take(DeviceMirror& other) {
    owner_ = std::move(other.owner_);
    device_ = other.device_;
    bytes_ = other.bytes_;
    other.device_ = nullptr;
    other.bytes_ = 0;
  }
  std::shared_ptr<const void> owner_;  // keeps the device allocation alive
  const void* device_ = nullptr;
  size_t bytes_ = 0;
};

}  // namespace nebula
