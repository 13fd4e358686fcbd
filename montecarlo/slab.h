#pragma once
// Plane-parallel slab (refractive index 1) for validating the transport
// against exact radiative-transfer results: diffuse reflectance and total
// transmittance under a collimated beam.
#include <cstdint>
#include <string>

#include "core/backend.h"
#include "montecarlo/photon_transport.h"

namespace nebula {

class Progress;

struct SlabParams {
  double albedo = 0.9;
  double g = 0.75;
  double tau = 2.0;            // optical thickness (extinction)
  double incidence_deg = 0.0;  // angle from the normal
  uint64_t photons = 1000000;
  uint64_t seed = 1;
  bool forced_first_scattering = true;
  Roulette roulette;
};

// A collimated beam entering the slab at the origin.
struct SlabBeam {
  Vec3 incident;
  NEBULA_HD void emit(float, float, float, PhotonState& st) const {
    st.pos = {0.0f, 0.0f, 0.0f};
    st.dir = incident;
  }
};

struct SlabRun {
  SlabGeometry geometry;
  SlabBeam source;
  Medium medium;  // sigma_ext = 1: lengths in mean free paths
  Roulette roulette;
  PhotonStream stream;
  bool forced_first;
};

struct SlabTallies {
  uint64_t sum_r = 0, sum_r2 = 0;  // diffuse reflectance per photon
  uint64_t sum_t = 0, sum_t2 = 0;  // total transmittance per photon
  uint64_t unscattered = 0, events = 0, capped = 0, capped_weight = 0;
};

struct SlabResult {
  SlabParams params;
  double R_diffuse = 0, R_stderr = 0;
  double T_total = 0, T_stderr = 0;
  double T_unscattered = 0;  // exp(-tau / cos(incidence)), exact
  uint64_t scattering_events = 0, capped_photons = 0;
  double capped_weight = 0;
  double seconds = 0;
  std::string device;
};

// Throws ParameterError naming the field of the first bad parameter.
void validate(const SlabParams& p);
SlabRun make_slab_run(const SlabParams& p);
SlabResult simulate_slab(const SlabParams& p, Backend backend, Progress* progress = nullptr);
SlabTallies simulate_slab_cpu(const SlabParams& p, Progress* progress);
SlabTallies simulate_slab_cuda(const SlabParams& p, Progress* progress);

// Adds the weight photon `photon` deposits into the slab tallies; host/device.
NEBULA_HD void run_slab_photon(const SlabRun& run, uint32_t photon, SlabTallies& t) {
  PhotonState st;
  float transmitted = 0.0f, reflected = 0.0f;
  Fate f = Fate::Flying;
  while (f == Fate::Flying) {
    float left_unscattered;
    f = transport_step(run.geometry, run.medium, run.roulette, run.source, run.forced_first,
                       run.stream.block(photon, st.draw), st, left_unscattered);
    // Unscattered light leaves through the far face.
    transmitted += left_unscattered;
    t.unscattered += to_fixed(left_unscattered);
  }
  t.events += st.orders;
  if (f == Fate::Escaped) {
    (st.dir.z > 0.0f ? transmitted : reflected) += st.weight();
  } else if (f == Fate::Capped) {
    ++t.capped;
    t.capped_weight += to_fixed(st.weight());
  }
  t.sum_r += to_fixed(reflected);
  t.sum_r2 += to_fixed(reflected * reflected);
  t.sum_t += to_fixed(transmitted);
  t.sum_t2 += to_fixed(transmitted * transmitted);
}

}  // namespace nebula
