#pragma once
// A scene rendered again and again under edits: parameter sweeps (`nebula
// sweep`), the Python module, a viewer. The session keeps the last scene's
// grids and its view-independent preparation; each render applies its
// overrides to the scene text and redoes only what they change: the grids
// only when [density], [emission] or the bands change, the star bakes only
// when the grid or the stars' positions do, the diffuse field when the dust,
// the tables or the stars' light do (prepare_grid's re-preparing overload).
// A camera edit costs the frame alone. A [spectral] scene keeps its depth
// bakes, model and fields alike (prepare_spectral's `previous`).
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/render_scene.h"
#include "pipeline/shared_diffuse.h"

namespace nebula {

struct PreparedSpectral;  // pipeline/spectral_scene.h

class RenderSession {
 public:
  // A scene file, or TOML text (`name` in messages, `base_dir` for its
  // relative paths), with overrides applied to every render.
  static RenderSession from_file(const std::string& path, std::vector<std::string> overrides, RenderOptions options);
  static RenderSession from_text(std::string text, std::string name, std::string base_dir,
                                 std::vector<std::string> overrides, RenderOptions options);

  // The scene under the session's overrides, then these ("KEY=VALUE", as
  // load_scene takes them). Errors name the scene and the key.
  const Scene& load(const std::vector<std::string>& overrides = {});
  // The fast render of that scene (render_scene's image, metadata and report).
  RenderOutput render(const std::vector<std::string>& overrides = {});
  // The ground truth of that scene (truth_scene; nothing is reused: it bakes nothing).
  TruthRenderOutput truth(const std::vector<std::string>& overrides, const TruthOptions& options);

  // Renders to come (a sweep's points, as override lists): those whose
  // diffuse fields differ only in the dust's albedos share one photon pass
  // per band (pipeline/shared_diffuse.h), baked when the first of them
  // renders; the others' fields wait in memory until theirs. Per point: its
  // sharing group and its field (equal numbers, equal fields; -1: shares
  // nothing), so that a caller can render a group's points together. Errors
  // as load's, naming the point's key. A later plan replaces this one; plan({}) ends it.
  struct PlannedPoint {
    int group = -1, field = -1;
  };
  std::vector<PlannedPoint> plan(const std::vector<std::vector<std::string>>& points);

  const RenderOptions& options() const { return options_; }
  RenderOptions& options() { return options_; }

 private:
  RenderSession() = default;
  std::unique_ptr<Scene> load_detached(const std::vector<std::string>& overrides) const;
  // A planned field for `scene` into `previous` (baking its group's share
  // first when needed); false when there is none.
  bool hand_shared_field(const Scene& scene, PreparedGrid& previous);
  std::string text_, name_, base_dir_;
  std::vector<std::string> overrides_;
  RenderOptions options_;
  // The last scene (on the heap: the preparation points into it) and its preparation.
  std::unique_ptr<Scene> scene_, retired_;
  std::unique_ptr<PreparedGrid> prepared_;
  std::shared_ptr<const PreparedSpectral> spectral_;  // a [spectral] scene's preparation, instead
  // The plan: per group, its fields not yet baked (bands and tables, taken
  // while planning); fields baked ahead, by key.
  struct PlanGroup {
    std::vector<SharedDiffuseMember> members;
  };
  std::vector<PlanGroup> groups_;
  std::map<std::string, SharedDiffuse> ready_;
};

}  // namespace nebula
