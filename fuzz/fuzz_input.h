#pragma once
// Helpers of the libFuzzer harnesses (fuzz_loaders.cpp): the loaders read
// files, so each input is written to one scratch file per process first.
#include <cstddef>
#include <cstdint>
#include <string>

namespace nebula::fuzz {

// Writes the bytes to <tmp>/nebula-fuzz-PID/input<extension> and returns the path.
std::string input_file(const uint8_t* data, size_t size, const std::string& extension);

// Reads in this process (NEBULA_HDF5_IN_PROCESS=1): a crash must reach libFuzzer,
// not be turned into an error by a child process. With NEBULA_FUZZ_CHILD=1
// set, the production path instead (each HDF5 file read in a child first):
// then any crash that reaches libFuzzer escaped the child-process guard.
void read_in_process();

}  // namespace nebula::fuzz
