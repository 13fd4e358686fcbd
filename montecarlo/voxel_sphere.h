#pragma once
// One row of the scattering table: photons falling on the voxel sphere of
// scattering depth tau_sct per voxel edge (edge l = 1), host/device.
#include <cstdint>

#include "core/angular_binning.h"
#include "core/hd.h"
#include "core/math.h"
#include "montecarlo/photon_transport.h"

namespace nebula {

enum class Beam : int {
  Parallel = 0,  // uniform over the sphere's cross-section (default)
  Pencil = 1,    // the 2005 paper's ray through the centre
};

inline const char* to_string(Beam b) { return b == Beam::Parallel ? "parallel" : "pencil"; }

// Light falling on the voxel sphere along +z.
struct SphereBeam {
  Beam beam;
  float radius;
  // u and the azimuth place the photon uniformly on the cross-section (parallel)
  // or at the near pole (pencil).
  NEBULA_HD void emit(float u, float sin_phi, float cos_phi, PhotonState& st) const {
    if (beam == Beam::Parallel) {
      const float rho = radius * sqrtf(u);
      st.pos = {rho * cos_phi, rho * sin_phi, -sqrtf(fmaxf(radius * radius - rho * rho, 0.0f))};
    } else {
      st.pos = {0.0f, 0.0f, -radius};
    }
    st.dir = {0.0f, 0.0f, 1.0f};
  }
};

struct SphereRow {
  SphereGeometry geometry;
  SphereBeam source;
  Medium medium;
  Roulette roulette;
  PhotonStream stream;
  AngularBins bins;
  bool forced_first;
  float inv_weight_scale;  // tallies hold weight / scale, kept in [0, 2)
  uint32_t photons;        // traced in this row (photons_of_row)
};

NEBULA_HD Fate sphere_step(const SphereRow& row, uint32_t photon, PhotonState& st,
                           float& unscattered) {
  return transport_step(row.geometry, row.medium, row.roulette, row.source, row.forced_first,
                        row.stream.block(photon, st.draw), st, unscattered);
}

}  // namespace nebula

namespace nebula {

// Books a finished photon into a sink (CPU: per-task arrays; GPU: shared
// memory), so both backends tally the same way. Sink provides
// add_bin(k, x_fixed, x2_fixed) and add_capped(x_fixed).
template <class Sink>
NEBULA_HD void tally_sphere_photon(const SphereRow& row, const PhotonState& st, Fate fate,
                                   Sink& sink) {
  const float x = st.weight() * row.inv_weight_scale;
  if (fate == Fate::Escaped) {
    // mu is the cosine between the incident direction (+z) and the exit direction.
    sink.add_bin(row.bins.bin_of(st.dir.z), to_fixed(x), to_fixed(x * x));
  } else if (fate == Fate::Capped) {
    sink.add_capped(to_fixed(x));
  }
}

}  // namespace nebula
