#include "raycast/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>

#include "core/error.h"
#include "core/placement.h"
#include "core/progress.h"
#include "raycast/diffuse_light.h"
#include "raycast/host_copy.h"
#include "raycast/march_scene.h"
#include "illumination/star_pixels_cpu.h"
#include "raycast/voxel_sources.h"

namespace nebula {

void validate(const RenderInputs& in) {
  if (!in.density) throw Error("render: no density grid");
  const size_t voxels = in.density->shape.count();
  if (in.density->tau_v.size() != voxels) throw Error("render: density has the wrong number of voxels");
  if (!(in.mode.step_voxels >= 0.0f) || (in.mode.step_voxels > 0 && in.mode.step_voxels < 1e-3f))
    throw Error("render: the smooth mode's step must be 0 (exact) or at least 1e-3 voxels");
  if (in.bands.empty() || in.bands.size() > size_t(kMaxBands))
    throw Error("render: 1 to " + std::to_string(kMaxBands) + " bands required");
  for (const RenderBand& b : in.bands) {
    if (b.albedo > 0 && !b.table) throw Error("render: band " + b.name + " scatters but has no table");
    if (b.emission && b.emission->size() != voxels)
      throw Error("render: emission of band " + b.name + " does not match the density grid");
  }
  for (const BakedStar& s : in.stars) {
    if (s.power.size() != in.bands.size()) throw Error("render: a star lacks band powers");
    if (!s.depth_v || s.depth_v->size() != voxels) throw Error("render: a star has no baked depth");
  }
  if (const DiffuseField* f = in.diffuse) {
    const GridShape& g = in.density->shape;
    const int edge = 1 << f->shift;
    if (f->n_bands() != in.bands.size() || f->cells.nx != (g.nx + edge - 1) / edge ||
        f->cells.ny != (g.ny + edge - 1) / edge || f->cells.nz != (g.nz + edge - 1) / edge)
      throw Error("render: the diffuse field was baked for another grid or other bands");
    if (!f->has_harmonics())
      throw Error("render: the diffuse field's harmonics have the wrong size");
  }
}

namespace {

// The field's per-view pass on the CPU into light[b], peak[b] (sized here, per
// band with a field), which the scene then reads.
void diffuse_light_pass_cpu(MarchScene& scene, const Camera& camera, std::vector<std::vector<float>>& light,
                            std::vector<std::vector<float>>& peak) {
  const GridShape& g = scene.density.shape;
  DiffuseLightPlanes planes;
  for (int b = 0; b < scene.n_bands; ++b)
    if (scene.diffuse.has[b]) {
      light[b].assign(g.count(), 0.0f);
      peak[b].assign(g.count(), 0.0f);
      planes.band[b] = light[b].data();
      planes.peak[b] = peak[b].data();
      scene.diffuse_light[b] = planes.band[b];
      scene.diffuse_peak[b] = planes.peak[b];
    }
  dispatch_diffuse_degree(scene.diffuse.degree, [&](auto degree) {
    dispatch_zonal(scene, [&](auto zonal) {
      tbb::parallel_for(tbb::blocked_range<int>(0, g.ny * g.nz), [&](const auto& rows) {
        for (int r = rows.begin(); r != rows.end(); ++r)
          diffuse_light_row<degree(), zonal()>(scene, camera, r % g.ny, r / g.ny, 0, g.nx, planes);
      });
    });
  });
}

}  // namespace

DiffuseLightArrays diffuse_light_arrays(const RenderInputs& in, Backend backend) {
  validate(in);
  if (!in.diffuse) throw Error("diffuse light: no diffuse field");
  if (backend == Backend::Cuda) return diffuse_light_arrays_cuda(in);
  HostPlacement host;
  MarchScene scene = assemble_march_scene(in, host);
  DiffuseLightArrays out;
  out.light.resize(kMaxBands);
  out.peak.resize(kMaxBands);
  diffuse_light_pass_cpu(scene, in.camera, out.light, out.peak);
  out.light.resize(in.bands.size());
  out.peak.resize(in.bands.size());
  out.device_light.resize(in.bands.size());
  out.device_peak.resize(in.bands.size());
  return out;
}

Image render_cpu(const RenderInputs& in, RenderStats* stats) {
  HostPlacement host;
  MarchScene scene = assemble_march_scene(in, host);
  Image image(in.camera.width, in.camera.height, band_names(in.bands));
  std::atomic<uint64_t> clamps{0};
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<float>> light(kMaxBands), peak(kMaxBands);
  if (in.mode.voxel_sources) {
    // The preview: every voxel's light towards the eye, once (raycast/voxel_sources.h).
    const GridShape& g = scene.density.shape;
    VoxelSourcePlanes planes;
    for (int b = 0; b < scene.n_bands; ++b) {
      light[b].resize(g.count());
      planes.band[b] = light[b].data();
      scene.voxel_source[b] = planes.band[b];
      if (scene.has_diffuse && scene.diffuse.has[b]) {
        peak[b].assign(g.count(), 0.0f);
        planes.peak[b] = peak[b].data();
        scene.diffuse_peak[b] = planes.peak[b];
      }
    }
    dispatch_source_degree(scene, [&](auto degree) {
      dispatch_zonal(scene, [&](auto zonal) {
        tbb::parallel_for(tbb::blocked_range<int>(0, g.ny * g.nz), [&](const auto& rows) {
          int local = 0;
          for (int r = rows.begin(); r != rows.end(); ++r)
            local += voxel_source_row<degree(), zonal()>(scene, in.camera, r % g.ny, r / g.ny, 0, g.nx, planes);
          clamps += uint64_t(local);
        });
      });
    });
  } else if (scene.has_diffuse) {
    diffuse_light_pass_cpu(scene, in.camera, light, peak);
  }
  dispatch_march(scene, in.mode, [&](auto smooth, auto diffuse, auto voxel_sources, auto zonal) {
    constexpr bool exact = !smooth() && !voxel_sources();
    tbb::parallel_for(tbb::blocked_range<int>(0, in.camera.height), [&](const auto& rows) {
      uint64_t local_clamps = 0;
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < in.camera.width; ++x) {
          Vec3 origin, dir;
          if (!in.camera.ray(x, y, origin, dir)) continue;
          // Rays near a star average its phase over their chords' angles (ray_march.h).
          const RayResult r =
              exact && passes_near_a_star(scene, origin, dir)
                  ? march_ray<smooth(), diffuse(), voxel_sources(), zonal(), exact>(scene, origin, dir, in.mode)
                  : march_ray<smooth(), diffuse(), voxel_sources(), zonal()>(scene, origin, dir, in.mode);
          store_radiance(r, scene.n_bands, in.exposure, image.pixels.data(), image.width, image.height, x, y);
          local_clamps += r.table_clamps;
        }
      clamps += local_clamps;
      if (in.progress) in.progress->add(rows.size());
    });
    if constexpr (exact) {
      // The pixels at each star's image, with many rays each (illumination/star_pixels.h).
      if (marches_star_pixels(in))
        march_star_pixels_cpu(in.camera, star_positions(in.stars), scene.n_bands, in.exposure, image.pixels.data(),
                            [&](Vec3 origin, Vec3 dir, float narrowing, float* out, size_t stride) {
                              MarchScene sub = scene;
                              sub.footprint = sub_pixel_footprint(scene.footprint, narrowing);
                              const RayResult r =
                                  march_ray<false, diffuse(), false, zonal(), true>(sub, origin, dir, in.mode);
                              for (int b = 0; b < scene.n_bands; ++b) out[size_t(b) * stride] = r.radiance[b];
                              return uint64_t(r.table_clamps);
                            },
                            clamps);
    }
  });
  if (stats) {
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats->table_clamps = clamps;
  }
  return image;
}

void parallel_copy(float* to, const float* from, size_t n) {
  constexpr size_t kChunk = size_t(1) << 18;  // 1 MiB of floats per task
  tbb::parallel_for(tbb::blocked_range<size_t>(0, (n + kChunk - 1) / kChunk), [&](const auto& chunks) {
    for (size_t c = chunks.begin(); c != chunks.end(); ++c) {
      const size_t begin = c * kChunk, count = std::min(kChunk, n - begin);
      std::memcpy(to + begin, from + begin, count * sizeof(float));
    }
  });
}

Image render(const RenderInputs& in, Backend backend, RenderStats* stats) {
  return backend == Backend::Cuda ? render_cuda(in, stats) : render_cpu(in, stats);
}

}  // namespace nebula
