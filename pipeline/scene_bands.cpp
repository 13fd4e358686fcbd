#include "pipeline/scene_bands.h"

#include <algorithm>

#include "illumination/extinction.h"
#include "illumination/filters.h"
#include "illumination/star.h"

namespace nebula {

bool is_grey_band(const std::string& name) { return name == kGreyBand; }

Passband band_filter(const Scene& scene, const std::string& name) {
  const auto own = std::find_if(scene.filters.begin(), scene.filters.end(),
                                [&](const SceneFilter& f) { return f.name == name; });
  return own != scene.filters.end() ? own->passband
         : is_grey_band(name)       ? Passband{kGreyBand, {}, {}}
                                    : load_filter(name);
}

SceneBands scene_bands(const Scene& scene) {
  SceneBands out;
  for (const std::string& name : scene.bands) out.filters.push_back(band_filter(scene, name));
  const Passband V = load_filter("V");
  for (size_t b = 0; b < scene.bands.size(); ++b) {
    const double ratio = is_grey_band(scene.bands[b])
                             ? 1.0
                             : extinction_ratios({out.filters[b]}, V, scene.dust.R_V, scene.dust.law)[0];
    out.bands.push_back(Band{scene.bands[b], static_cast<float>(ratio), static_cast<float>(scene.dust.albedo[b]),
                             static_cast<float>(scene.dust.g[b])});
  }
  for (const SceneStar& star : scene.stars) {
    StarLight light{star.position, {}};
    for (const Passband& filter : out.filters) {
      const double fraction = filter.wavelength_nm.empty() ? 1.0 : band_fraction(star.temperature_K, filter);
      light.power.push_back(static_cast<float>(star.luminosity_lsun * fraction));
    }
    out.stars.push_back(light);
  }
  return out;
}

}  // namespace nebula
