#pragma once
// The band physics of a scene (DESIGN.md section 3, "Bands"): every renderer
// sees a scene's bands and stars through this, computed in one place.
#include <string>
#include <vector>

#include "core/bands.h"
#include "illumination/passband.h"
#include "scene/scene.h"

namespace nebula {

// The grey band ("grey", core/bands.h): one wavelength, as radiative-transfer
// benchmarks use. Its dust extinguishes as in V (A/A_V = 1 under every law)
// and each star puts its whole bolometric luminosity in it.
bool is_grey_band(const std::string& name);

struct SceneBands {
  // Per scene band, from the filter registry; the grey band's is empty (no
  // wavelengths), so it has no pivot wavelength.
  std::vector<Passband> filters;
  // Per scene band: its name; A_b/A_V, the scene's extinction law (and R_V)
  // averaged over the filter and normalised to the V filter's, so V is
  // exactly 1; the scene's albedo and g in that band.
  std::vector<Band> bands;
  // Per star: its position and, per band, its bolometric luminosity times the
  // fraction of its black body the filter passes (L_sun in the band).
  std::vector<StarLight> stars;
};

SceneBands scene_bands(const Scene& scene);

// The filter a band name stands for in a scene: the scene's own [filters]
// entry, else the registry's (load_filter; Error for an unknown name). The
// grey band has no filter: an empty passband named "grey" holds its place.
Passband band_filter(const Scene& scene, const std::string& name);

}  // namespace nebula
