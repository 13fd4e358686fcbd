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

// What a scene's diffuse field depends on, as prepare_grid compares it:
// `photons`, what its photons depend on (the grid, the stars, the field's
// settings, each band's extinction and g: not the albedos or tables), and
// `field`, that with the albedos and tables (PreparedGrid::diffuse_key).
// Both empty when the scene bakes no field (axial, another mode, nothing
// scatters, no star) or cannot be compared (a grid built in code).
struct DiffuseKeys {
  std::string photons, field;
};
DiffuseKeys diffuse_keys(const Scene& scene, const SceneBands& bands, const RenderOptions& options);

// One member of a shared bake, taken from its scene (which need not be kept).
struct SharedDiffuseMember {
  DiffuseKeys keys;
  SceneBands bands;
  BandTables tables;  // resolved (loaded or made) as prepare_grid would
};

struct SharedDiffuse {
  std::string key;
  DiffuseField field;
  DiffuseReport report;  // shared_with: the other members
};
// The fields of members with `scene`'s photon key (checked: Error
// otherwise), at most kMaxAlbedoSlots, on `scene`'s grid.
std::vector<SharedDiffuse> bake_shared_diffuse(const Scene& scene, const std::vector<SharedDiffuseMember>& members,
                                               const RenderOptions& options);

}  // namespace nebula
