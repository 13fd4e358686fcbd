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

struct SphereRow {
  SphereGeometry geometry;
  Medium medium;
  Roulette roulette;
  PhotonStream stream;
  AngularBins bins;
  Beam beam;
  bool forced_first;
  float inv_weight_scale;  // tallies hold weight / scale, kept in [0, 2)
};

// Places photon `photon` on the sphere moving along +z and makes its first
// flight. Returns the unscattered weight; `alive` says whether it scatters.
NEBULA_HD float launch_sphere_photon(const SphereRow& row, uint32_t photon, PhotonState& st,
                                     bool& alive) {
  const Uniform4 u = row.stream.block(photon, 0);
  const float r = row.geometry.radius;
  if (row.beam == Beam::Parallel) {
    // Uniform on the disc of radius r, entering on the sphere's near side.
    const float rho = r * sqrtf(u.u0);
    float s, c;
    sin_cos_2pi(u.u1, s, c);
    st.pos = {rho * c, rho * s, -sqrtf(fmaxf(r * r - rho * rho, 0.0f))};
  } else {
    st.pos = {0.0f, 0.0f, -r};
  }
  st.dir = {0.0f, 0.0f, 1.0f};
  st.weight_albedo = 1.0f;
  st.draw = 1;
  st.orders = 0;
  return first_flight(row.geometry, row.medium, row.forced_first, u.u2, st, alive);
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
