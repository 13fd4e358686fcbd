#include "multires/pyramid_render.h"

#include <chrono>

#include "core/error.h"
#include "illumination/optical_depth_bake.h"
#include "multires/image_pyramid.h"
#include "multires/volume_pyramid.h"

namespace nebula {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

PreparedPyramid prepare_pyramid(const RenderInputs& in, int levels, Backend backend) {
  validate(in);
  // build_volume_pyramid's range check (and message), before any coarse work.
  if (levels < 0 || levels > max_pyramid_levels(in.density->shape)) build_volume_pyramid(*in.density, levels);
  std::vector<Vec3> positions;
  for (const BakedStar& s : in.stars) positions.push_back(s.position);
  PreparedPyramid out;
  out.levels.reserve(levels);
  for (int j = 1; j <= levels; ++j) {
    const auto t0 = std::chrono::steady_clock::now();
    const PyramidLevelData* below = j == 1 ? nullptr : &out.levels.back();
    const DensityGrid& fine = below ? below->density : *in.density;
    PyramidLevelData level;
    level.density = downsample(fine);
    level.emission.resize(in.bands.size());
    for (size_t b = 0; b < in.bands.size(); ++b) {
      const std::vector<float>* fine_emission =
          below ? (below->emission[b].empty() ? nullptr : &below->emission[b]) : in.bands[b].emission;
      if (fine_emission) level.emission[b] = downsample_edge_integral(fine.shape, *fine_emission);
    }
    level.report.level = j;
    level.report.shape = level.density.shape;
    level.report.pyramid_seconds = seconds_since(t0);
    if (!in.stars.empty()) {
      BakeResult bake = bake_star_depths(level.density, positions, backend);
      level.report.bake_seconds = bake.seconds;
      level.depth = std::move(bake.tau_v);
    }
    out.levels.push_back(std::move(level));
  }
  return out;
}

RenderInputs level_inputs(const RenderInputs& in, const PyramidLevelData& level, const Camera& camera) {
  if (level.emission.size() != in.bands.size() || level.depth.size() != in.stars.size())
    throw Error("pyramid: level " + std::to_string(level.report.level) + " was prepared for other bands or stars");
  RenderInputs out = in;
  out.progress = nullptr;
  out.density = &level.density;
  out.diffuse = nullptr;  // the pyramid is the other way to add light between voxels
  for (size_t b = 0; b < in.bands.size(); ++b)
    out.bands[b].emission = level.emission[b].empty() ? nullptr : &level.emission[b];
  for (size_t k = 0; k < in.stars.size(); ++k) out.stars[k].depth_v = &level.depth[k];
  out.camera = camera;
  return out;
}

PyramidResult render_pyramid(const RenderInputs& in, const PreparedPyramid& prepared, Backend backend,
                             bool keep_levels) {
  if (backend == Backend::Cuda && !prepared.levels.empty()) return render_pyramid_cuda(in, prepared, keep_levels);
  PyramidResult out;
  RenderStats stats;
  out.levels.push_back(render(in, backend, &stats));
  PyramidLevelReport r0;
  r0.shape = in.density->shape;
  r0.width = in.camera.width;
  r0.height = in.camera.height;
  r0.render_seconds = stats.seconds;
  r0.table_clamps = stats.table_clamps;
  out.report.push_back(r0);
  Camera camera = in.camera;
  for (const PyramidLevelData& level : prepared.levels) {
    camera = coarser_camera(camera);
    out.levels.push_back(render(level_inputs(in, level, camera), backend, &stats));
    PyramidLevelReport r = level.report;
    r.width = camera.width;
    r.height = camera.height;
    r.render_seconds = stats.seconds;
    r.table_clamps = stats.table_clamps;
    out.report.push_back(r);
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (out.levels.size() == 1 && !keep_levels) {
    out.image = std::move(out.levels[0]);  // one level: the image itself (a frame's copy saved)
    out.levels.clear();
  } else {
    out.image = combine_pyramid(out.levels);
  }
  out.combine_seconds = seconds_since(t0);
  return out;
}

PyramidResult render_pyramid(const RenderInputs& in, int levels, Backend backend, bool keep_levels) {
  const PreparedPyramid prepared = prepare_pyramid(in, levels, backend);
  return render_pyramid(in, prepared, backend, keep_levels);
}

}  // namespace nebula
