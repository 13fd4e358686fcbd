#pragma once
#include <string>

namespace nebula {

// Where physics kernels run. Auto picks CUDA when a device is usable.
enum class Backend { Cpu, Cuda };

inline const char* to_string(Backend b) { return b == Backend::Cpu ? "cpu" : "cuda"; }

}  // namespace nebula
