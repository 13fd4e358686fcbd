#pragma once
// The CUDA path's placement (core/placement.h): every array a renderer's
// kernel reads is uploaded into a DeviceArray owned here, freed with the
// placement. For .cu files only.
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "core/device_array.h"

namespace nebula {

class DevicePlacement {
 public:
  // A device copy of `v`.
  template <class T>
  const T* place(const std::vector<T>& v) {
    bytes_ += v.size() * sizeof(T);
    return upload(v);
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
