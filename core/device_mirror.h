#pragma once
// A device copy kept beside a host array that no longer changes once made (a
// baked diffuse field, say): the CUDA path uploads it once, or its producer
// leaves its own device result there, and every later kernel reads that copy
// instead of uploading the array again. Host code sees only an opaque
// handle, so builds without CUDA carry it for free. Whoever changes the host
// array must reset() its mirror; a copy of the owner starts without one
// (the copy may be changed: it uploads its own), a move takes it along.
#include <cstddef>
#include <memory>

namespace nebula {

struct DeviceMirror {
  DeviceMirror() = default;
  DeviceMirror(const DeviceMirror&) {}
  DeviceMirror& operator=(const DeviceMirror&) {
    reset();
    return *this;
  }
  DeviceMirror(DeviceMirror&&) noexcept = default;
  DeviceMirror& operator=(DeviceMirror&&) noexcept = default;

  std::shared_ptr<const void> owner;  // keeps the device allocation alive
  const void* device = nullptr;
  size_t bytes = 0;

  bool holds(size_t host_bytes) const { return device != nullptr && bytes == host_bytes; }
  void reset() {
    owner.reset();
    device = nullptr;
    bytes = 0;
  }
};

}  // namespace nebula
