#pragma once
// Diffuse fields shared between renders that differ only in the dust's
// albedos (a sweep over the albedo): one photon pass per band serves them all
// (diffuse/diffuse_bake.h, bake_diffuse_shared; docs/sweep.md). A field made
// here goes to prepare_grid through its `previous` argument (diffuse,
// diffuse_key, report.diffuse), which then uses it instead of baking.
#include <string>
#include <vector>

#include "diffuse/diffuse_field.h"
#include "pipeline/render_scene.h"

namespace nebula {

// What the photons of a scene's diffuse field depend on: the grid, the stars,
// the field's settings and each band's extinction and g, not the albedos or
// tables. Empty when the scene bakes no field (axial, another mode, nothing
// scatters, no star) or cannot be compared (a grid built in code).
std::string diffuse_photon_key(const Scene& scene, const RenderOptions& options);
// The key prepare_grid gives the scene's field (PreparedGrid::diffuse_key):
// the photon key with the albedos and tables. Empty as above.
std::string diffuse_field_key(const Scene& scene, const RenderOptions& options);

// One member of a shared bake, taken from its scene (which need not be kept).
struct SharedDiffuseMember {
  std::string key;  // diffuse_field_key
  SceneBands bands;
  BandTables tables;  // resolved (loaded or made) as prepare_grid would
};
SharedDiffuseMember shared_diffuse_member(const Scene& scene, const RenderOptions& options);

struct SharedDiffuse {
  std::string key;
  DiffuseField field;
  DiffuseReport report;  // shared_with: the other members
};
// The fields of members with one photon key (checked: Error otherwise), at
// most kMaxAlbedoSlots, on `scene`'s grid (one of theirs).
std::vector<SharedDiffuse> bake_shared_diffuse(const Scene& scene, const std::vector<SharedDiffuseMember>& members,
                                               const RenderOptions& options);

}  // namespace nebula
