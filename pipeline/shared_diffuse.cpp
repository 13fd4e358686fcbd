#include "pipeline/shared_diffuse.h"

#include <chrono>
#include <memory>

#include "core/error.h"
#include "core/progress.h"
#include "diffuse/diffuse_bake.h"
#include "pipeline/run_setup.h"

namespace nebula {

using namespace pipeline_detail;

std::vector<SharedDiffuse> bake_shared_diffuse(const Scene& scene, const std::vector<SharedDiffuseMember>& members,
                                               const RenderOptions& o) {
  const std::string photons = diffuse_keys(scene, scene_bands(scene), o).photons;
  if (members.empty() || photons.empty()) throw Error("shared diffuse bake: nothing to bake");
  std::vector<std::vector<DiffuseBand>> sets;
  for (const SharedDiffuseMember& m : members) {
    if (m.keys.photons != photons) throw Error("shared diffuse bake: the members differ beyond their albedos");
    sets.push_back(diffuse_bands(m.bands, m.tables));
  }
  const auto t0 = std::chrono::steady_clock::now();
  const DiffuseBakeOptions options = diffuse_options(scene);
  // The progress bar counts the passes: bands that scatter in some member.
  std::vector<DiffuseBand> any = sets.front();
  for (const std::vector<DiffuseBand>& set : sets)
    for (size_t b = 0; b < any.size(); ++b) any[b].albedo = std::max(any[b].albedo, set[b].albedo);
  std::unique_ptr<Progress> bar = diffuse_progress(any, options, o);
  std::vector<DiffuseBakeStats> stats;
  std::vector<DiffuseField> fields =
      bake_diffuse_shared(scene.density, sets, members.front().bands.stars, options, o.backend, &stats, bar.get());
  if (bar) bar->finish();
  const double wall = seconds_since(t0);
  std::vector<SharedDiffuse> out(members.size());
  for (size_t i = 0; i < members.size(); ++i) {
    out[i].key = members[i].keys.field;
    out[i].report = diffuse_report(sets[i], options, fields[i], 1 << fields[i].shift, stats[i], wall);
    out[i].report.shared_with = static_cast<int>(members.size()) - 1;
    out[i].field = std::move(fields[i]);
  }
  return out;
}

}  // namespace nebula
