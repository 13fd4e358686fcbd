#pragma once
#include <cstdint>
#include <vector>

#include "tables/scattering_table.h"
#include "tables/table_lookup.h"

namespace nebula {

// P copied to GPU memory for kernels to look up through view(). Owns the
// allocation; movable, not copyable. In a build without CUDA the
// constructor throws Error.
class DeviceTable {
 public:
  explicit DeviceTable(const ScatteringTable& table);
  ~DeviceTable();
  DeviceTable(DeviceTable&& other) noexcept;
  DeviceTable& operator=(DeviceTable&& other) noexcept;
  DeviceTable(const DeviceTable&) = delete;
  DeviceTable& operator=(const DeviceTable&) = delete;

  // P points to device memory: pass it to kernels, never dereference on the host.
  TableView view() const { return view_; }

 private:
  void release();

  float* device_P_ = nullptr;
  TableView view_;
};

// TableView::lookup at every (tau[j], mu[j]) in a CUDA kernel, for tests and
// batch use. When clamped_count is not null it receives the number of
// clamped lookups. Throws Error without CUDA or on a CUDA failure.
std::vector<float> lookup_batch_gpu(const ScatteringTable& table, const std::vector<float>& tau,
                                    const std::vector<float>& mu, uint64_t* clamped_count);

}  // namespace nebula
