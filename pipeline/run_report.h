#pragma once
// What a run computed, and why: data the pipeline fills and front ends show
// (the command line prints it, app/print_report.cpp; a viewer would draw it).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/backend.h"
#include "core/grid.h"
#include "illumination/extinction.h"
#include "multires/pyramid_render.h"
#include "truth/path_tracer.h"

namespace nebula {

struct BandReport {
  std::string name;
  double extinction_ratio = 1;  // A_b / A_V
  double albedo = 0, g = 0;
  bool scatters = false;        // has a table (albedo > 0, and something to light)
};

// Where a band's scattering table came from.
enum class TableOrigin { File, Cache, Generated };
const char* to_string(TableOrigin origin);  // "read", "cache", "generated"

struct TableReport {
  double albedo = 0, g = 0;
  std::vector<std::string> bands;  // the bands that use this table
  TableOrigin origin = TableOrigin::Cache;
  std::string path;                // the file read, or the cache entry
  double seconds = 0;              // reading or generating it
  std::string warning;             // a damaged or foreign cache entry that was generated again
  double noise = 0;                // the median relative standard error of its entries (P_stderr / P)
  uint64_t photons_per_row = 0;
};

struct BakeReport {
  bool done = false;    // false: nothing scatters or no star (nothing to bake)
  size_t stars = 0;
  uint64_t cells = 0;   // voxels, or texels of an axial map
  double seconds = 0;
  bool reused = false;  // taken over from an earlier preparation (prepare_grid after an edit)
};

// The diffuse field's bake (diffuse/diffuse_bake.h).
struct DiffuseReport {
  bool done = false;
  bool reused = false;  // taken over from an earlier preparation (its figures are that bake's)
  int shared_with = 0;  // other albedo sets baked by the same photon passes (a sweep; its figures are theirs)
  int order = 0;
  int zonal = 0;               // zonal degrees of the brightest stars' light (0: none)
  int zonal_stars = 0;
  bool lanczos = false;        // the response tapered by Lanczos's sigma factors (render.diffuse_taper)
  GridShape cells;             // the field's cells ({along the axis, from it, 1} for an axial map)
  int voxels_per_cell = 1;     // along each axis
  bool axial = false;          // an axial map's field: photons on `photon_grid`, the map voxelized
  GridShape photon_grid;
  uint64_t photons_per_band = 0;
  size_t bands = 0;            // bands baked (those that scatter)
  double seconds = 0;          // the photon passes (CUDA events on the GPU)
  double wall_seconds = 0;     // the whole bake, responses included
  std::vector<double> noise;   // per scene band: relative L2 noise of the field's l = 0 part; -1: no field
  std::vector<std::string> names;  // the baked bands' names where they are not the scene's (spectral: the nodes)
  size_t stars = 0;  // fields baked star by star (spectral; 0: all stars in one)
  uint64_t collisions = 0, crossings = 0, capped = 0;
  size_t field_bytes = 0, work_bytes = 0;
};

struct AxialMapReport {
  std::string source;   // synthetic, file or image, with its name
  int nx = 0, nr = 0;
  double texel_pc = 0;
  size_t emission_planes = 0;
  int height_max = 0;   // the height map's global maximum
  double build_seconds = 0;
  std::string skip, skip_used;  // requested and run (naive when the map has no empty texel)
  double step_texels = 0;
  size_t map_bytes = 0;     // the map and its skip structures
  size_t render_bytes = 0;  // everything the march reads (with depths and tables)
};

struct TruthReport {
  int spp = 0;
  uint64_t seed = 0;
  int max_orders = 0;
  std::string transmittance;  // "ratio" or "exact"
  bool equiangular = false;
  uint64_t paths = 0;
  PathCounters counters;
  GridShape axial_grid;  // an axial map's voxelization in its own frame (nx = 0: a 3D grid scene)
};

// The spectral renderer's run (pipeline/spectral_render.cpp, docs/spectral.md).
struct SpectralFilterReport {
  std::string name;
  double from_nm = 0, to_nm = 0, pivot_nm = 0;
  int segments = 0;        // of its piecewise cubic
  double fit_error = 0;    // largest |cubic - measured| / peak
};
struct SpectralReport {
  std::string method;             // double, analytic, projection, light_density, voxel_light
  int basis = 0;                  // elements used (the greedy may stop short)
  int wavelengths = 0;            // double: samples
  int breaks = 0;                 // analytic: the filters' (and stars', continua's) breaks shared by all
  std::string attenuation, norm;  // law or inverse; relative or absolute
  double lo_um = 0, hi_um = 0;    // the wavelength range of the basis and samples
  double fit_depth = 0, max_depth = 0;
  std::vector<double> elements;   // the chosen family members' optical paths a (V band)
  double basis_error = 0;         // the greedy's largest residual over its family with all elements
  int accumulators = 0;           // numbers each ray carries (the emission's included)
  int emission_lines = 0, emission_continua = 0;  // [[spectral.emission]] components
  std::vector<SpectralFilterReport> filters;
  int table_nodes = 0;            // attenuations the voxels' table is read at; 0: the thin limit (no table)
  std::vector<double> node_kappa; // their kappa = tau / tau_V
  std::vector<double> node_albedo, node_g;  // albedo and g varying with wavelength: each node's ([spectral.dust])
  double model_seconds = 0;       // fits, basis and tables (host)
  double resolve_seconds = 0;     // accumulators to one plane per filter
  double diffuse_view_seconds = 0;  // light between voxels: the field's per-view pass and the voxels' terms
  // The model's basis and tables taken over from an earlier preparation
  // (prepare_spectral's `previous`), new filters put on them when they changed.
  bool basis_kept = false;
};

struct RunReport {
  std::string scene;          // the scene's path ("demo" for the built-in one)
  std::string renderer;       // "grid", "axial", "truth" or "spectral"
  std::string mode;           // "exact", "smooth step 0.5 voxel", "axial distance step 0.5 texel", "truth spp 16 ..."
  Backend backend = Backend::Cpu;
  std::string camera;         // the projection's name
  int width = 0, height = 0;
  GridShape grid;             // grid and truth renders
  size_t stars = 0;
  double R_V = 0;
  ExtinctionLaw law = ExtinctionLaw::CCM89;
  std::vector<BandReport> bands;
  std::vector<TableReport> tables;
  BakeReport bake;
  std::string multiple_scattering;  // "diffuse", "pyramid" or "none"
  DiffuseReport diffuse;
  bool emission = false;
  std::vector<PyramidLevelReport> pyramid;  // grid renders: level 0 first
  std::optional<AxialMapReport> axial;
  std::optional<TruthReport> truth;
  std::optional<SpectralReport> spectral;
  double render_seconds = 0;  // marching or tracing only (CUDA events on the GPU)
  uint64_t table_clamps = 0;  // table lookups beyond tau_max (clamped)
  // The pixels at the stars' images marched with many rays each
  // (render.star_pixels; illumination/star_pixels.h): 0 when off or none.
  int star_pixels = 0, star_pixel_cells = 0, star_pixel_rays = 0;
  double total_seconds = 0;
};

}  // namespace nebula
