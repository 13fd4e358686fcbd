#include "pipeline/scene_bands.h"

#include <algorithm>

#include "illumination/extinction.h"
#include "illumination/filters.h"
#include "illumination/star.h"

namespace nebula {

SceneBands scene_bands(const Scene& scene) {
  SceneBands out;
  for (const std::string& name : scene.bands) {
    const auto own = std::find_if(scene.filters.begin(), scene.filters.end(),
                                  [&](const SceneFilter& f) { return f.name == name; });
    out.filters.push_back(own != scene.filters.end() ? own->passband : load_filter(name));
  }
  const std::vector<double> ratios =
      extinction_ratios(out.filters, load_filter("V"), scene.dust.R_V, scene.dust.law);
  for (size_t b = 0; b < scene.bands.size(); ++b)
    out.bands.push_back(Band{scene.bands[b], static_cast<float>(ratios[b]), static_cast<float>(scene.dust.albedo[b]),
                             static_cast<float>(scene.dust.g[b])});
  for (const SceneStar& star : scene.stars) {
    const std::vector<double> fractions = band_fractions(star.temperature_K, out.filters);
    StarLight light{star.position, {}};
    for (double f : fractions) light.power.push_back(static_cast<float>(star.luminosity_lsun * f));
    out.stars.push_back(light);
  }
  return out;
}

}  // namespace nebula
