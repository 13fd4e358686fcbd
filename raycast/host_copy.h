#pragma once
// Copies n floats from `from` to `to` on every core (TBB): the CUDA frame's
// last step, from its pinned staging buffer to the frame's pixels, where one
// core's memcpy would take longer than the download itself.
#include <cstddef>

namespace nebula {

void parallel_copy(float* to, const float* from, size_t n);

}  // namespace nebula
