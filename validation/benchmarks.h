#pragma once
// Speed studies behind docs/performance.md: the tabulator (throughput and
// error against photons) and the illumination bake.
#include <cstdint>
#include <string>
#include <vector>

#include "core/backend.h"
#include "diffuse/diffuse_bake.h"
#include "montecarlo/tabulate.h"
#include "multires/pyramid_render.h"

namespace nebula {

struct ThroughputResult {
  std::string backend, device;
  TabulateParams params;
  int repeats = 0;
  double median_seconds = 0;  // transport time (CUDA events on the GPU), median of repeats
  double median_wall = 0;     // end to end, allocation and copies included
  double photons_per_second = 0, events_per_second = 0, events_per_photon = 0;
};

// One warm-up run, then `repeats` timed runs; medians.
ThroughputResult bench_throughput(Backend backend, const TabulateParams& p, int repeats);

struct ConvergenceRow {
  uint64_t photons_per_row = 0;
  double seconds = 0;       // transport time
  double rel_l2_error = 0;  // ||P - P_ref|| / ||P_ref|| over the whole table
  double predicted = 0;     // the same from the stated standard errors
  double rms_z = 0;         // RMS of (P - P_ref) / sqrt(se^2 + se_ref^2): ~1 if errors are honest
};

// Error against an independent reference with `ref_factor` times the largest
// photon count (another seed), for each photon count in `counts`.
std::vector<ConvergenceRow> bench_convergence(Backend backend, const TabulateParams& base,
                                              const std::vector<uint64_t>& counts, int ref_factor);


struct BakeBenchResult {
  std::string backend;
  int size = 0, stars = 0, repeats = 0;
  double median_seconds = 0;   // all stars, compute only (CUDA events on the GPU)
  double voxels_per_second = 0;  // star-voxel pairs per second
};

// Per-star optical-depth bake of a size^3 grid of Philox noise (tau_v in
// [0, 2)) lit by `stars` stars, one inside the grid and the rest outside.
BakeBenchResult bench_bake(Backend backend, int size, int stars, int repeats);

}  // namespace nebula

namespace nebula {

struct RenderBenchRow {
  std::string backend;
  int width = 0, height = 0, size = 0, stars = 0;
  double median_seconds = 0;  // marching only (CUDA events on the GPU)
  double rays_per_second = 0;
};

// Frames of the procedural nebula (scene/, default parameters, size^3
// voxels) lit by 1, 2, 4, ... `max_stars` stars (the first at the nebula's
// star), seen from outside with a perspective camera, with a table tabulated
// on the same backend (a = g = 0.6, 10^4 photons per row).
std::vector<RenderBenchRow> bench_render(Backend backend, int size, int width, int height, int max_stars,
                                         int repeats);

// The diffuse field on the same nebula with one star (bands B, V, R, a = g =
// 0.6): the bake after a change of the dust or the star (the star's depth bake
// and the photon passes, medians of `repeats`), and frames without and with
// the field (medians), with the field's memory and noise. star_pixels false:
// one ray per pixel at the star's image too (what the star's own pixels cost).
struct DiffuseBench {
  std::string backend;
  int size = 0, width = 0, height = 0, degree = 0, cells = 0;
  uint64_t photons = 0;        // per band
  double star_bake_seconds = 0;  // the star's depth bake
  double photon_seconds = 0;     // the photon passes, three bands (CUDA events on the GPU)
  double bake_wall_seconds = 0;  // the whole diffuse bake, end to end (host clock)
  double frame_without = 0, frame_with = 0;  // seconds per frame
  size_t field_bytes = 0, work_bytes = 0, star_depth_bytes = 0;
  double noise = 0;  // relative L2 noise of the V band's l = 0 part
};
DiffuseBench bench_diffuse(Backend backend, int size, int width, int height, int repeats, int degree, int cells,
                           uint64_t photons, int zonal = 0, bool star_pixels = true);

// The cost of each pyramid level on the same nebula with one star: the
// one-time build and bake per level, and per frame the median render time of
// each level (1/2^j resolution) and of the host-side combination.
struct PyramidBench {
  std::string backend;
  int size = 0;
  double bake_seconds = 0;                 // level 0's bake
  std::vector<PyramidLevelReport> levels;  // render_seconds: medians
  double combine_seconds = 0;              // median, on the host
};
PyramidBench bench_pyramid(Backend backend, int size, int width, int height, int levels, int repeats);

}  // namespace nebula

namespace nebula {

struct TruthBenchRow {
  std::string backend;
  int width = 0, height = 0, size = 0, spp = 0;
  double median_seconds = 0;      // tracing only (CUDA events on the GPU)
  double vertices_per_second = 0; // real collisions (each with next-event estimation to the star)
  double paths_per_second = 0;    // one path per pixel, sample and band
  double spp_per_second = 0;      // samples per pixel (all three bands) per second at width x height
  double vertices_per_path = 0;
  int threads_per_pixel = 1;      // GPU threads sharing each pixel's samples
};

// The path tracer on the procedural nebula (as bench_render: default
// parameters at size^3 voxels, its star, the same camera), bands B, V, R with
// a = g = 0.6; one warm-up, then `repeats` timed runs at `spp`. Next-event
// transmittance by ratio tracking, or by the exact voxel sum.
TruthBenchRow bench_truth(Backend backend, int size, int width, int height, int spp, int repeats,
                          bool exact_transmittance = false, bool equiangular = false, int threads_per_pixel = 0);

}  // namespace nebula

#include <functional>

#include "axial/axial_march.h"

namespace nebula {

struct AxialBenchRow {
  std::string backend, map, mode;
  std::string ran;            // the mode that ran: naive when the map has no empty texel (step aside)
  int map_size = 0, width = 0, height = 0, inclination_deg = 0;
  double median_ms = 0;       // marching only (CUDA events on the GPU), median of the repeats
  double speedup = 0;         // naive's median / this mode's
  double max_difference = 0;  // largest |pixel - naive pixel| over naive's peak (0: bit-identical)
  uint64_t samples = 0;       // samples the rays stepped through (CPU only; 0 on the GPU)
  double diffuse_bake_ms = 0; // the map's diffuse field, baked once per map (with `diffuse`; 0 without)
  bool deformed = false;      // with the colour and shape deformations (the naive reference deformed alike)
  double empty_fraction = 0;  // the map's empty texels over all its texels
};

// The thesis' Tables 5.1-5.5 (Khalass 2021): each synthetic map of
// map_size x map_size texels (1 pc along the axis), seen by an orthographic
// camera of width x height pixels framing the map at each inclination,
// rendered in each of `modes` (empty: every one; naive always runs first, as
// the reference of the speed-ups and differences) at a step of step_texels; one
// warm-up, then the median of `repeats`. With `star`, a B-type star on the
// axis at the map's centre lights the dust (full physics, a = g = 0.6, three
// bands); without it, emission-absorption only. Rows go to on_row as they come.
// step_aside false runs the skip code even on maps without empty texels (to
// measure its overhead there). `diffuse` (with a star) adds the map's diffuse
// field (axial/axial_diffuse.h: degree 3, 64 cells, 2^20 photons per band),
// baked once per map. Each of `deforms` (default: none) runs every mode again,
// the naive march under the same deformations as its reference. star_pixels
// false: one ray per pixel at the star's image too.
void bench_axial(Backend backend, int map_size, int width, int height, int repeats, float step_texels,
                 const std::vector<std::string>& maps, const std::vector<int>& inclinations, bool star,
                 const std::function<void(const AxialBenchRow&)>& on_row, bool step_aside = true,
                 std::vector<AxialSkip> modes = {}, bool diffuse = false,
                 const std::vector<AxialDeformSettings>& deforms = {AxialDeformSettings{}},
                 bool star_pixels = true);

// The deformations `nebula bench axial` times (the thesis' "with deformations"
// columns do not state theirs): colour and shape noise of `kind`, colour
// amplitude 0.5, shape pull up to 0.2, frequency 4 per map length, 4 octaves.
AxialDeformSettings bench_axial_deformations(NoiseKind kind);

}  // namespace nebula
