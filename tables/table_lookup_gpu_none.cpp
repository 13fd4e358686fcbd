#include "core/error.h"
#include "tables/device_table.h"

namespace nebula {

// This build has no CUDA backend: every GPU entry point says so.
namespace {
[[noreturn]] void no_cuda(const char* what) {
  throw Error(std::string(what) + ": nebula was built without CUDA");
}
}  // namespace

DeviceTable::DeviceTable(const ScatteringTable&) { no_cuda("DeviceTable"); }
DeviceTable::~DeviceTable() = default;
DeviceTable::DeviceTable(DeviceTable&& other) noexcept : view_(other.view_) {}
DeviceTable& DeviceTable::operator=(DeviceTable&&) noexcept { return *this; }
void DeviceTable::release() {}

std::vector<float> lookup_batch_gpu(const ScatteringTable&, const std::vector<float>&,
                                    const std::vector<float>&, uint64_t*) {
  no_cuda("lookup_batch_gpu");
}

}  // namespace nebula
