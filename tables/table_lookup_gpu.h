#pragma once
// TableView::lookup on the GPU, for tests and batch use.
#include <cstdint>
#include <vector>

#include "tables/scattering_table.h"

namespace nebula {

// The lookup at every (tau[j], mu[j]) in a CUDA kernel. When clamped_count is
// not null it receives the number of clamped lookups. Throws Error without
// CUDA or on a CUDA failure.
std::vector<float> lookup_batch_gpu(const ScatteringTable& table, const std::vector<float>& tau,
                                    const std::vector<float>& mu, uint64_t* clamped_count);

}  // namespace nebula
