#pragma once
// Where a renderer's inputs live while its kernel reads them. Each renderer
// assembles its kernel scene (a struct of pointers, passed by value) in one
// function templated on the placement: HostPlacement hands back the host
// arrays themselves (the CPU path), DevicePlacement (core/device_placement.h,
// .cu files only) uploads copies it owns (the CUDA path). The two paths then
// differ only in where the arrays live, never in how the scene is put together.
#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/device_mirror.h"

namespace nebula {

class HostPlacement {
 public:
  // The caller's array itself (it must outlive the render).
  template <class T>
  const T* place(const std::vector<T>& v) {
    bytes_ += v.size() * sizeof(T);
    return v.data();
  }
  // The same for an array with a device mirror (unused on the host).
  template <class T>
  const T* place(const std::vector<T>& v, DeviceMirror&) {
    return place(v);
  }
  // An array that may live on the device only: fetch() gives the host copy.
  // A fetch() that makes the array (returns it by value) has it kept here.
  template <class Fetch>
  auto place_mirrored(DeviceMirror&, size_t, Fetch&& fetch) {
    if constexpr (std::is_reference_v<decltype(fetch())>)
      return place(fetch());
    else
      return keep(fetch());
  }
  // An array made while assembling (per-star views, say), kept alive here.
  template <class T>
  const T* keep(std::vector<T> v) {
    auto held = std::make_shared<std::vector<T>>(std::move(v));
    held_.push_back(held);
    return held->data();
  }
  // Bytes of the arrays given to place(): what the kernel reads.
  size_t bytes() const { return bytes_; }

 private:
  std::vector<std::shared_ptr<const void>> held_;
  size_t bytes_ = 0;
};

}  // namespace nebula
