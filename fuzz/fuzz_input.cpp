#include "fuzz/fuzz_input.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace nebula::fuzz {

std::string input_file(const uint8_t* data, size_t size, const std::string& extension) {
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("nebula-fuzz-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / ("input" + extension)).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return path;
}

void read_in_process() {
  // NEBULA_FUZZ_CHILD=1 fuzzes the production path instead: every HDF5 file
  // read in a child first, so a libhdf5 crash must come back as an Error.
  if (!std::getenv("NEBULA_FUZZ_CHILD")) setenv("NEBULA_HDF5_IN_PROCESS", "1", 1);
}

}  // namespace nebula::fuzz
