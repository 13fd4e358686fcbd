#pragma once
// The CUDA path's placement (core/placement.h): every array a renderer's
// kernel reads is uploaded into a DeviceArray owned here, freed with the
// placement. For .cu files only.
#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/device_array.h"
#include "core/device_mirror.h"

namespace nebula {

class DevicePlacement {
 public:
  // A device copy of `v`.
  template <class T>
  const T* place(const std::vector<T>& v) {
    bytes_ += v.size() * sizeof(T);
    return upload(v);
  }
  // The array's device mirror, uploaded into it first when it holds none:
  // an array that does not change is uploaded once for every later kernel.
  template <class T>
  const T* place(const std::vector<T>& v, DeviceMirror& mirror) {
    return place_mirrored(mirror, v.size(), [&]() -> const std::vector<T>& { return v; });
  }
  // The same for an array that may live on the device only (`count`
  // elements): fetch() gives the host copy, called only to upload.
  template <class Fetch>
  auto place_mirrored(DeviceMirror& mirror, size_t count, Fetch&& fetch) {
    using T = typename std::decay_t<decltype(fetch())>::value_type;
    bytes_ += count * sizeof(T);
    const DeviceMirror::Copy copy = mirror.get_or_upload(count * sizeof(T), [&] {
      auto array = std::make_shared<DeviceArray<T>>(fetch());
      return DeviceMirror::Copy{array, array->get()};
    });
    held_.push_back(copy.owner);
    return static_cast<const T*>(copy.device);
  }
  // The same for an array made while assembling (not counted in bytes()).
  template <class T>
  const T* keep(std::vector<T> v) {
    return upload(v);
  }
  // Bytes of the arrays given to place(): what the kernel reads.
  size_t bytes() const { return bytes_; }

 private:
  template <class T>
  const T* upload(const std::vector<T>& v) {
    auto array = std::make_shared<DeviceArray<T>>(v);
    held_.push_back(array);
    return array->get();
  }
  std::vector<std::shared_ptr<const void>> held_;
  size_t bytes_ = 0;
};

}  // namespace nebula
