#pragma once
#include <string>

#include "core/error.h"
#include "core/gpu.h"

namespace nebula {

// Where physics kernels run. Auto picks CUDA when a device is usable.
enum class Backend { Cpu, Cuda };

inline const char* to_string(Backend b) { return b == Backend::Cpu ? "cpu" : "cuda"; }

// Parses "cpu", "cuda" or "auto"; `option` names the flag in the error.
inline Backend parse_backend(const std::string& s, const std::string& option = "--backend") {
  if (s == "cpu") return Backend::Cpu;
  if (s == "cuda" || s == "gpu") {
    std::string why;
    if (!gpu_available(&why)) throw Error(option + ": cuda requested but " + why);
    return Backend::Cuda;
  }
  if (s == "auto") return gpu_available() ? Backend::Cuda : Backend::Cpu;
  throw Error(option + ": expected cpu, cuda or auto, got '" + s + "'");
}

}  // namespace nebula
