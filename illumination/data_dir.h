#pragma once
#include <string>

namespace nebula {

// The folder holding the project's data files (filters/, ...): the value of
// the environment variable NEBULA_DATA_DIR when it is set and not empty,
// otherwise the source tree's data/ folder, compiled in as an absolute path
// so that tests and tools find it from any working directory.
std::string default_data_dir();

}  // namespace nebula
