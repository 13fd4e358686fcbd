// The reconstructed map as the HDF5 file `[axial] file = ...` reads
// (scene/density_sources.h: load_axial_plane_hdf5).
#include <hdf5.h>

#include <mutex>

#include "core/atomic_file.h"
#include "core/error.h"
#include "hdf5io/hdf5_support.h"
#include "reconstruct/reconstruct.h"

namespace nebula {
namespace {

using hdf5io::Handle;
using hdf5io::with_reason;

void write_plane(hid_t file, const std::string& name, const AxialMap& map, const std::vector<float>& plane) {
  const hsize_t dims[2] = {hsize_t(map.nr), hsize_t(map.nx)};
  Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose);
  if (!space.valid()) throw Error(with_reason("creating the dataspace of " + name));
  Handle set(H5Dcreate2(file, name.c_str(), H5T_IEEE_F32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid()) throw Error(with_reason("creating " + name));
  if (H5Dwrite(set.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, plane.data()) < 0)
    throw Error(with_reason("writing " + name));
  if (!set.close()) throw Error(with_reason("closing " + name));
}

}  // namespace

void write_axial_map_hdf5(const AxialMap& map, const std::vector<std::string>& bands, const std::string& path,
                          bool overwrite, const std::string& emission_prefix) {
  check_axial_map(map, "cannot write " + path);
  if (!map.emission.empty() && map.emission.size() != bands.size())
    throw Error("cannot write " + path + ": " + std::to_string(map.emission.size()) + " emission planes for " +
                std::to_string(bands.size()) + " band names");
  check_output_target(path, overwrite, "folder", true);
  TemporaryFile temporary(path);
  {
    std::lock_guard<std::mutex> lock(hdf5io::hdf5_mutex());
    hdf5io::silence_hdf5_errors();
    try {
      Handle file(H5Fcreate(temporary.path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
      if (!file.valid()) throw Error(with_reason("creating the HDF5 file"));
      write_plane(file.get(), "tau_v", map, map.tau_v);
      for (size_t b = 0; b < map.emission.size(); ++b)
        write_plane(file.get(), emission_prefix + bands[b], map, map.emission[b]);
      if (!file.close()) throw Error(with_reason("closing the HDF5 file"));
    } catch (const Error& e) {
      throw Error("cannot write " + path + ": " + e.what());
    }
  }
  temporary.publish();
}

}  // namespace nebula
