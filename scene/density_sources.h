#pragma once
// Where a scene's dust comes from: an HDF5 dataset, a FITS cube or the
// built-in procedural reflection nebula. Every source returns tau_v per voxel
// (DESIGN.md section 3) and refuses NaN, infinite or negative values, zero
// sizes and grids that would not fit in memory, with one-line Errors naming
// the file (or parameter), the dataset and the reason.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/grid.h"
#include "core/vec3.h"

namespace nebula {

// ------------------------------------------------------------ shared checks

// Half the physical memory: sysconf(_SC_PHYS_PAGES) * page size / 2.
size_t grid_memory_limit_bytes();

// Refuses an nx x ny x nz grid of `bytes_per_voxel` if any size is zero or
// the bytes needed exceed `limit_bytes`; `what` names the file and dataset
// (or parameter) in the message.
void check_grid_size(const std::string& what, uint64_t nx, uint64_t ny, uint64_t nz,
                     uint64_t bytes_per_voxel = sizeof(float),
                     uint64_t limit_bytes = grid_memory_limit_bytes());

// Refuses the first NaN, infinite or negative value, naming `what`, the
// voxel (x, y, z), its linear index and the value.
void check_grid_values(const std::string& what, const GridShape& shape,
                       const std::vector<float>& values, const char* quantity = "tau_v");

// ------------------------------------------------------------ files

// A 3D dataset [nz][ny][nx] (C order, x fastest) of any float or integer
// type, read as float. Attribute `voxel_size` (parsecs, > 0) and optional
// `origin` (3 numbers, parsecs, the grid's minimum corner; default 0) are
// looked up on the dataset first, then on the file's root group.
DensityGrid load_density_hdf5(const std::string& path, const std::string& dataset = "tau_v");

// The primary image of a FITS file, a 3D cube with NAXIS1 = nx (fastest),
// NAXIS2 = ny, NAXIS3 = nz, any BITPIX (BSCALE/BZERO applied, BLANK pixels
// refused), read as float. Voxel size from CDELT1 = CDELT2 = CDELT3 (> 0,
// CUNITi absent or "pc"), or `voxel_size_pc` when the file has no CDELT;
// both present and different is an Error. voxel_size_pc = 0 means "from the
// file". Origin 0 unless every axis has CRPIXi and CRVALi, then
// origin_i = CRVALi + (0.5 - CRPIXi) * CDELTi (FITS pixel centres are at
// integer pixel coordinates counted from 1).
DensityGrid load_density_fits(const std::string& path, double voxel_size_pc = 0);

// An emission grid (one band) from an HDF5 dataset with the density's shape
// [nz][ny][nx]; a `voxel_size` attribute, if present, must match. Values
// must be finite and >= 0.
std::vector<float> load_emission_hdf5(const std::string& path, const std::string& dataset,
                                      const GridShape& density_shape);

// A 2D dataset [nr][nx] (C order, x fastest: x along an axial map's axis, r
// away from it) of any float or integer type, read as float; values must be
// finite and >= 0 (`quantity` names them in messages).
std::vector<float> load_axial_plane_hdf5(const std::string& path, const std::string& dataset, int& nx, int& nr,
                                         const char* quantity = "tau_v");

// ------------------------------------------------------------ procedural

// The 2005 paper's section 4.3 kind of reflection nebula (Magnor et al.,
// "Reflection Nebula Visualization", IEEE Visualization 2005): a star in a
// low-density bubble swept by its wind, a dense shell around the bubble, dust
// falling off exponentially outside, an optically thick far side and 3D
// fractal noise. The functional forms are ours (docs/scene.md).
//
// Lengths are fractions of the cube edge and densities are tau_v per cube
// edge (the V-band optical depth of a path one cube edge long at that
// density; a voxel gets value / n), so the same parameters describe the same
// cloud at every resolution n and every physical size size_pc.
struct ProceduralParams {
  int n = 128;             // voxels per cube edge
  double size_pc = 2.0;    // cube edge, parsecs
  Vec3 origin_pc{0, 0, 0};  // the cube's minimum corner, parsecs
  uint64_t seed = 1;       // noise seed (Philox4x32-10 key)

  Vec3 star{0.5f, 0.5f, 0.5f};  // star position, fractions of the edge

  Vec3 wind_direction{0, -1, 0.5f};  // the bubble centre lies from the star along this
  double bubble_offset = 0.06;       // star-to-bubble-centre distance, < bubble_radius
  double bubble_radius = 0.2;
  double bubble_tau = 0.5;           // density inside the bubble

  double shell_thickness = 0.06;  // FWHM of the shell's Gaussian radial profile
  double shell_tau = 24.0;        // shell peak density (at bubble_radius + thickness / 2)

  double cloud_tau = 6.0;      // ambient density just outside the bubble
  double scale_length = 0.15;  // e-folding length of the ambient fall-off

  Vec3 near_side{0, -1, 0};     // from the star towards the camera side
  double far_multiplier = 4.0;  // density factor in the half-space beyond the star
  double far_transition = 0.03;  // smoothstep width of the change, 0 = a sharp plane

  double noise_amplitude = 0.8;  // density *= exp(amplitude * noise), noise in [-1, 1]
  double noise_frequency = 3.0;  // base frequency, cycles per cube edge
  int noise_octaves = 5;
  double noise_gain = 0.5;        // amplitude ratio of successive octaves
  double noise_lacunarity = 2.0;  // frequency ratio of successive octaves

  // Issue 13's structure (each off by default, so older scenes keep their dust):
  // the far side's boundary moved behind the star and warped by the noise, so a
  // side view shows no straight cut through the star; and filaments, ridged
  // noise: density *= exp(filament_amplitude * (ridge - 1/2)), ridge in [0, 1]
  // high on thin sheets where independent noise crosses zero.
  double far_offset = 0.0;         // the boundary lies this far beyond the star (fraction of the edge)
  double far_warp = 0.0;           // and moves by far_warp x the fractal noise
  double filament_amplitude = 0.0;
  double filament_frequency = 4.0;  // cycles per cube edge of the first ridged octave
  int filament_octaves = 3;         // each twice the frequency and half the weight of the one before
  double filament_sharpness = 6.0;  // ridge = (1 - |noise|)^sharpness: higher, thinner filaments
  double edge_fade = 0.0;  // density falls smoothly to 0 over this fraction of the edge at the cube's faces
};

// The first parameter outside its range (docs/scene.md), or nothing.
struct ParameterIssue {
  std::string parameter;  // the field's name, e.g. "bubble_offset"
  std::string reason;     // e.g. "is 0.3; must be less than bubble_radius = 0.2 (...)"
};
std::optional<ParameterIssue> check_procedural(const ProceduralParams& params);

// Throws Error "<parameter>: <reason>" for the first issue.
void validate_procedural(const ProceduralParams& params);

// tau_v per voxel, finite and >= 0; identical for identical parameters
// (any thread count). Validates first.
DensityGrid procedural_nebula(const ProceduralParams& params);

// The star's world position (parsecs): origin_pc + size_pc * star.
Vec3 procedural_star_position(const ProceduralParams& params);

// The fractal value noise in [-1, 1] at a point of the unit cube (fractions
// of the edge), as used by procedural_nebula at resolution n (octaves above
// n / 2 cycles per edge are left out; the normalisation keeps them).
double procedural_noise(const ProceduralParams& params, double u, double v, double w);

}  // namespace nebula
