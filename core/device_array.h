#pragma once
// The one owner of device memory: an array that frees itself; CUDA errors
// become nebula::Error. For .cu files only (needs the CUDA runtime).
#include <cuda_runtime.h>

#include <algorithm>
#include <vector>

#include "core/cuda_check.h"

namespace nebula {

template <class T>
class DeviceArray {
 public:
  // n zeroed elements.
  explicit DeviceArray(size_t n) : size_(n) {
    NEBULA_CUDA_CHECK(cudaMalloc(&ptr_, std::max<size_t>(1, n) * sizeof(T)));
    NEBULA_CUDA_CHECK(cudaMemset(ptr_, 0, std::max<size_t>(1, n) * sizeof(T)));
  }
  // A copy of `host`.
  explicit DeviceArray(const std::vector<T>& host) : size_(host.size()) {
    NEBULA_CUDA_CHECK(cudaMalloc(&ptr_, std::max<size_t>(1, size_) * sizeof(T)));
    upload(host.data());
  }
  ~DeviceArray() { cudaFree(ptr_); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;

  T* get() const { return ptr_; }
  size_t size() const { return size_; }
  size_t bytes() const { return size_ * sizeof(T); }
  void upload(const T* host) {
    if (size_) NEBULA_CUDA_CHECK(cudaMemcpy(ptr_, host, bytes(), cudaMemcpyHostToDevice));
  }
  void download(T* host) const {
    if (size_) NEBULA_CUDA_CHECK(cudaMemcpy(host, ptr_, bytes(), cudaMemcpyDeviceToHost));
  }

 private:
  T* ptr_ = nullptr;
  size_t size_ = 0;
};

}  // namespace nebula
