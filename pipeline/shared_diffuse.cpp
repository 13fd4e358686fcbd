#include "pipeline/shared_diffuse.h"

#include <chrono>
#include <memory>

#include "core/error.h"
#include "core/progress.h"
#include "diffuse/diffuse_bake.h"
#include "pipeline/run_setup.h"

namespace nebula {

using namespace pipeline_detail;

SharedDiffuseMember shared_diffuse_member(const Scene& scene, const RenderOptions& o) {
  SharedDiffuseMember m;
  m.key = diffuse_field_key(scene, o);
  if (m.key.empty()) throw Error(scene.path + ": its diffuse field cannot be shared (no field, or a grid built in code)");
  m.bands = scene_bands(scene);
  m.tables = resolve_tables(scene, {o.backend, o.table_photons, o.progress});
  return m;
}

std::vector<SharedDiffuse> bake_shared_diffuse(const Scene& scene, const std::vector<SharedDiffuseMember>& members,
                                               const RenderOptions& o) {
  const std::string photons = diffuse_photon_key(scene, o);
  if (members.empty() || photons.empty()) throw Error("shared diffuse bake: nothing to bake");
  std::vector<std::vector<DiffuseBand>> sets;
  for (const SharedDiffuseMember& m : members) {
    if (m.key.compare(0, photons.size(), photons) != 0)
      throw Error("shared diffuse bake: the members differ beyond their albedos");
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
    out[i].key = members[i].key;
    out[i].report = diffuse_report(sets[i], options, fields[i], 1 << fields[i].shift, stats[i], wall);
    out[i].report.shared_with = static_cast<int>(members.size()) - 1;
    out[i].field = std::move(fields[i]);
  }
  return out;
}

}  // namespace nebula
