// libFuzzer harnesses of the loaders of users' files (issue 17): one binary
// per loader, chosen by NEBULA_FUZZ_LOADER at compile time. Every input must
// end in a value or an Error; a crash, a sanitizer report or an exception of
// another type is a finding. Run by scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "imageio/image_output.h"
#include "scene/density_sources.h"
#include "scene/scene_file.h"
#include "tables/table_file.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  nebula::fuzz::read_in_process();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace nebula;
  try {
#if NEBULA_FUZZ_LOADER == 1  // scene text (TOML); data paths resolve into a folder that does not exist
    load_scene_text(std::string(reinterpret_cast<const char*>(data), size), "fuzz.toml", "/nonexistent-nebula-fuzz");
#elif NEBULA_FUZZ_LOADER == 2  // density HDF5
    load_density_hdf5(fuzz::input_file(data, size, ".h5"));
#elif NEBULA_FUZZ_LOADER == 3  // density FITS
    load_density_fits(fuzz::input_file(data, size, ".fits"), 0.1);
#elif NEBULA_FUZZ_LOADER == 4  // axial map plane (HDF5)
    int nx = 0, nr = 0;
    load_axial_plane_hdf5(fuzz::input_file(data, size, ".h5"), "tau_v", nx, nr);
#elif NEBULA_FUZZ_LOADER == 5  // scattering table
    read_table(fuzz::input_file(data, size, ".h5"));
#elif NEBULA_FUZZ_LOADER == 6  // image HDF5
    read_image(fuzz::input_file(data, size, ".h5"));
#elif NEBULA_FUZZ_LOADER == 7  // image FITS
    read_image(fuzz::input_file(data, size, ".fits"));
#else
#error "NEBULA_FUZZ_LOADER must be 1 to 7"
#endif
  } catch (const Error&) {
    // a refusal: what every bad input must get
  }
  return 0;
}
