#include "illumination/data_dir.h"

#include <cstdlib>

#ifndef NEBULA_DATA_DIR
#error "NEBULA_DATA_DIR must be defined by the build (illumination/CMakeLists.txt)"
#endif

namespace nebula {

std::string default_data_dir() {
  const char* from_environment = std::getenv("NEBULA_DATA_DIR");
  if (from_environment != nullptr && from_environment[0] != '\0') return from_environment;
  return NEBULA_DATA_DIR;
}

}  // namespace nebula
