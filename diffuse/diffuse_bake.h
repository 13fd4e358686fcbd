#pragma once
// The bake of the diffuse radiation field (docs/diffuse.md): per band, a
// Monte-Carlo photon pass from the stars through the grid (diffuse_photon.h),
// its track-length deposits summed into the field's harmonics, and each band's
// response from its scattering table. View-independent: a camera move reuses
// it; a change of the dust (albedo, g, R_V), the density or a star bakes again.
// CPU (TBB) and CUDA run the same photons and give the same sums.
#include <cstdint>
#include <vector>

#include "core/backend.h"
#include "core/bands.h"
#include "core/grid.h"
#include "diffuse/diffuse_field.h"
#include "diffuse/diffuse_photon.h"
#include "montecarlo/majorant_grid.h"

namespace nebula {

class Progress;

// A band as the bake reads it: a band with albedo > 0 needs its table (the
// response); a band with albedo 0 gets no field.
struct DiffuseBand : Band {
  const ScatteringTable* table = nullptr;
};

struct DiffuseBakeOptions {
  int degree = 3;                  // "diffuse_order": harmonics up to this degree, 0 to kMaxDiffuseDegree
  int cells = 64;                  // "diffuse_cells": the field's cells along the grid's longest axis (at least)
  uint64_t photons = 1u << 20;     // "diffuse_photons": per band, 1 to 2^32 - 1
  uint64_t seed = 1;
  int roulette_start = 3;          // collisions before Russian roulette plays
  int majorant_block = 4;          // voxels per majorant block edge
  int max_orders = 0;              // 0: every order; k > 0: light scattered at most k times (studies, tests)
  // CPU: host memory the pass may spend on accumulators of its own per thread
  // (plain adds); beyond it, or 0, the threads add into one set atomically.
  size_t private_sums_bytes = size_t(1) << 30;
  // Albedos sharing a pass: flights after collisions 1..this many deposit
  // once for all albedos (their weights applied after the pass), later ones
  // once per albedo. 0 to kMaxOrderBuckets; the same fields either way, up to
  // rounding. -1 (auto): 8 on the CPU (its per-thread sums' budget above), on
  // CUDA as many as kSharedBucketBytes holds, 8 to kMaxOrderBuckets
  // (shared_order_buckets_for).
  int shared_order_buckets = -1;
  // "diffuse_zonal": degrees degree + 1 .. this of each of the brightest
  // kMaxZonalStars stars' light, about the direction from the star (0: none).
  int zonal = 0;
  DiffuseTaper taper = DiffuseTaper::Auto;  // "diffuse_taper" (delta_m_response, resolved_taper)
  // Every band's photons draw the same random numbers (band 0's streams), so
  // that the fields of bands that differ a little (the spectral renderer's
  // attenuations) differ by their physics more than by their noise: the same
  // photon takes the same decisions until an attenuation changes one. Off:
  // each band its own streams (independent noise per band).
  bool common_streams = false;
};

// Device memory the order buckets of one shared CUDA pass may take (auto).
// More buckets mean fewer deposits per flight: at a = 0.9 a flight has
// survived n collisions with probability about 0.9^n, so beyond 8 buckets 43%
// of flights deposit once per albedo, beyond 32 3%; the deposits are
// atomics spread over the sums, which no longer fit the L2 cache.
constexpr size_t kSharedBucketBytes = size_t(2) << 30;

// The bucket count a shared pass uses: `options` unless auto (above).
int shared_order_buckets_for(const DiffuseBakeOptions& options, Backend backend, size_t cells, int n_coeffs);

struct DiffuseBakeStats {
  double seconds = 0;                // the photon passes (CUDA events on the GPU)
  uint64_t photons = 0;              // traced, all bands
  PhotonCounters counters;
  std::vector<double> noise;         // per band: relative L2 noise of the field's l = 0 part (its two halves); -1 without a field
  size_t field_bytes = 0;            // the field kept for rendering
  size_t work_bytes = 0;             // the pass's accumulators and copies, while it runs
};

// Throws ParameterError for an option out of range (named as above), Error
// for inputs that disagree (a scattering band without a table, power sizes).
DiffuseField bake_diffuse(const DensityGrid& density, const std::vector<DiffuseBand>& bands,
                          const std::vector<StarLight>& stars, const DiffuseBakeOptions& options, Backend backend,
                          DiffuseBakeStats* stats = nullptr, Progress* progress = nullptr);

// The fields of several sets of bands that differ only in their albedos (and
// so their tables), from one photon pass per band: the photons are traced at
// the band's largest albedo and deposit for every set (diffuse_photon.h,
// "slots"), at most kMaxAlbedoSlots sets. One field per set, in order, and
// per set its stats (the passes' time and counters are the shared passes').
// A set whose albedo is the largest gets the field bake_diffuse gives it, bit
// for bit; the others an estimate of theirs with their own noise (each
// set's noise is reported). Throws Error when the sets differ in anything
// but albedos and tables.
std::vector<DiffuseField> bake_diffuse_shared(const DensityGrid& density,
                                              const std::vector<std::vector<DiffuseBand>>& sets,
                                              const std::vector<StarLight>& stars, const DiffuseBakeOptions& options,
                                              Backend backend, std::vector<DiffuseBakeStats>* stats = nullptr,
                                              Progress* progress = nullptr);

// One band's photon pass, as both backends run it: the inputs, and the raw
// fixed-point sums with the pass's counters.
struct DiffusePassInputs {
  const DensityGrid* density = nullptr;
  const MajorantGrid* majorant = nullptr;
  std::vector<Vec3> stars;
  std::vector<float> star_cdf;
  Band band;
  uint32_t band_index = 0;
  uint32_t stream = 0;  // the photons' random streams: band_index, or 0 (DiffuseBakeOptions::common_streams)
  GridShape cells;
  int degree = 0;
  int zonal = 0, zonal_stars = 0;  // DiffuseField's: the stars' first zonal_stars have zonal blocks
  uint64_t seed = 1;
  int roulette_start = 3;
  int max_orders = 0;
  // Albedos to deposit for (empty: band.albedo alone); band.albedo is the
  // largest of them, the one the photons are traced at.
  std::vector<float> slot_albedos;
  int order_buckets = 0;          // with several slots: orders deposited once for all (DiffuseSlots)
  size_t private_sums_bytes = 0;  // DiffuseBakeOptions::private_sums_bytes (CPU)
  int slots() const { return slot_albedos.empty() ? 1 : static_cast<int>(slot_albedos.size()); }
};
// The pass's accumulator layout (diffuse_photon.h): slots, order buckets and
// each slot's albedo over the traced one (exactly 1 for the traced albedo).
DiffuseSlots diffuse_slots(const DiffusePassInputs& in, size_t cells, int n_coeffs);
struct DiffusePassResult {
  // CPU: the raw sums, 36.28 fixed point, two's complement, laid out as
  // DiffuseSlots says (the odd ones with one coefficient); empty from the GPU.
  std::vector<unsigned long long> sums, odd;
  // Per slot, [cell * slots + s]: the l = 0 sums of all photons and of the
  // odd ones, in fixed-point units (for the noise; the CPU's).
  std::vector<double> l0, odd_l0;
  // Per slot, the noise's sums (diffuse_cell_noise over the cells; the GPU's).
  std::vector<double> noise2, signal2;
  PhotonCounters counters;
  double seconds = 0;
  size_t host_bytes = 0;    // the accumulators (and downloads) the pass held on the host
  size_t device_bytes = 0;
};
DiffusePassResult diffuse_pass_cpu(const DiffusePassInputs& in, uint64_t photons, Progress* progress);

// A band's sums become its harmonics: sum x unit / (the grid's volume inside the cell).
NEBULA_HD double diffuse_cell_volume(const GridShape& grid, int shift, int x, int y, int z) {
  const int edge = 1 << shift;
  const int ix = grid.nx - (x << shift), iy = grid.ny - (y << shift), iz = grid.nz - (z << shift);
  return double(grid.voxel) * grid.voxel * grid.voxel * (ix < edge ? ix : edge) * (iy < edge ? iy : edge) *
         (iz < edge ? iz : edge);
}
NEBULA_HD float diffuse_coefficient(unsigned long long sum, double unit, double volume) {
  return static_cast<float>(double(static_cast<long long>(sum)) * unit / volume);
}
NEBULA_HD float diffuse_coefficient(double sum, double unit, double volume) {
  return static_cast<float>(sum * unit / volume);
}
// A cell's share of the field's relative L2 noise: `all` its l = 0 sum, `odd`
// that of the odd photons (even - odd has the noise of the whole sum), each
// over the cell's volume inside the grid.
NEBULA_HD void diffuse_cell_noise(double all, double odd, double volume, double& noise2, double& signal2) {
  noise2 += (all - 2 * odd) * (all - 2 * odd) / (volume * volume);
  signal2 += all * all / (volume * volume);
}

// Every band's pass on the GPU with the grid uploaded once; the harmonics are
// made from the sums there and stay there, in each slot's field's
// device_packed (a field has no host copy until host_packed() fetches one;
// `fields` has one field per slot, all passes having the same number of
// slots). Per pass (the order of `passes`): l0 and odd_l0 for the noise,
// counters and time.
std::vector<DiffusePassResult> diffuse_passes_cuda(const std::vector<DiffusePassInputs>& passes,
                                                   const std::vector<double>& units, uint64_t photons,
                                                   const GridShape& grid, const std::vector<DiffuseField*>& fields);

// The pass's kernel scene, assembled once for both backends (core/placement.h).
template <class Place>
DiffusePhotonScene assemble_photon_scene(const DiffusePassInputs& in, Place& place) {
  DiffusePhotonScene s;
  s.medium.density = {in.density->shape, place.place(in.density->tau_v, in.density->device_tau_v)};
  s.medium.majorant = in.majorant->view();
  s.medium.majorant.max_tau_v = place.place(in.majorant->max_tau_v);
  s.medium.majorant.min_tau_v = place.place(in.majorant->min_tau_v);
  s.ratio = in.band.extinction_ratio;
  s.albedo = in.band.albedo;
  s.g = in.band.g;
  s.cells = in.cells;
  s.degree = in.degree;
  s.n_sh = sh_count(in.degree);
  s.zonal = in.zonal > in.degree ? in.zonal : 0;
  s.zonal_stars = s.zonal > 0 ? in.zonal_stars : 0;
  s.n_coeffs = s.n_sh + s.zonal_stars * (s.zonal > 0 ? s.zonal - in.degree : 0);
  s.stars = place.place(in.stars);
  s.star_cdf = place.place(in.star_cdf);
  s.n_stars = static_cast<int>(in.stars.size());
  s.seed = in.seed;
  s.band = in.stream;
  s.roulette_start = in.roulette_start;
  s.max_orders = in.max_orders;
  const DiffuseSlots layout = diffuse_slots(in, in.cells.count(), s.n_coeffs);
  s.slots = layout.slots;
  s.order_buckets = layout.buckets;
  for (int k = 0; k < s.slots; ++k) s.slot_scale[k] = static_cast<float>(layout.scale[k]);
  return s;
}

}  // namespace nebula
