#include "raycast/pyramid_render.h"

#include <chrono>
#include <memory>

#include "illumination/optical_depth_bake.h"
#include "multires/image_pyramid.h"
#include "multires/volume_pyramid.h"

namespace nebula {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// One coarser level's data, owned here while RenderInputs points into it.
struct Level {
  DensityGrid density;
  std::vector<std::vector<float>> emission;  // per band; empty where the band has none
  std::vector<std::vector<float>> depth;     // per star
};

}  // namespace

PyramidResult render_pyramid(const RenderInputs& in, int levels, Backend backend) {
  validate(in);
  const int most = max_pyramid_levels(in.density->shape);
  PyramidResult out;
  RenderStats stats;
  out.levels.push_back(render(in, backend, &stats));
  out.report.push_back({0, in.density->shape, in.camera.width, in.camera.height, 0, 0, stats.seconds,
                        stats.table_clamps});
  if (levels == 0) {
    out.image = out.levels[0];
    return out;
  }
  // build_volume_pyramid's range check, before any coarse work is done.
  if (levels < 0 || levels > most) build_volume_pyramid(*in.density, levels);

  std::vector<Vec3> positions;
  for (const RenderStar& s : in.stars) positions.push_back(s.position);
  std::unique_ptr<Level> below, level;
  RenderInputs level_in = in;
  level_in.progress = nullptr;
  for (int j = 1; j <= levels; ++j) {
    const auto t0 = std::chrono::steady_clock::now();
    level = std::make_unique<Level>();
    const DensityGrid& fine = j == 1 ? *in.density : below->density;
    level->density = downsample(fine);
    level->emission.resize(in.bands.size());
    for (size_t b = 0; b < in.bands.size(); ++b) {
      const std::vector<float>* fine_emission = j == 1 ? in.bands[b].emission
                                                : below->emission[b].empty() ? nullptr
                                                                             : &below->emission[b];
      if (fine_emission) level->emission[b] = downsample_edge_integral(fine.shape, *fine_emission);
    }
    PyramidLevelReport r;
    r.level = j;
    r.shape = level->density.shape;
    r.pyramid_seconds = seconds_since(t0);
    if (!in.stars.empty()) {
      BakeResult bake = bake_star_depths(level->density, positions, backend);
      r.bake_seconds = bake.seconds;
      level->depth = std::move(bake.tau_v);
    }
    level_in.density = &level->density;
    for (size_t b = 0; b < in.bands.size(); ++b)
      level_in.bands[b].emission = level->emission[b].empty() ? nullptr : &level->emission[b];
    for (size_t k = 0; k < in.stars.size(); ++k) level_in.stars[k].depth_v = &level->depth[k];
    level_in.camera = coarser_camera(level_in.camera);
    r.width = level_in.camera.width;
    r.height = level_in.camera.height;
    out.levels.push_back(render(level_in, backend, &stats));
    r.render_seconds = stats.seconds;
    r.table_clamps = stats.table_clamps;
    out.report.push_back(r);
    below = std::move(level);
  }
  const auto t0 = std::chrono::steady_clock::now();
  out.image = combine_pyramid(out.levels, &out.differences);
  out.combine_seconds = seconds_since(t0);
  return out;
}

}  // namespace nebula
