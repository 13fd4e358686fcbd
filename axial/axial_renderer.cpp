#include "axial/axial_renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>

#include "axial/axial_scene.h"
#include "core/error.h"
#include "core/placement.h"
#include "core/progress.h"
#include "illumination/star_pixels_cpu.h"

namespace nebula {

const char* to_string(AxialSkip mode) {
  switch (mode) {
    case AxialSkip::Naive: return "naive";
    case AxialSkip::Empty: return "empty";
    case AxialSkip::GlobalMax: return "global_max";
    case AxialSkip::Omega: return "omega";
    case AxialSkip::OmegaMulti: return "omega_multi";
    case AxialSkip::Distance: return "distance";
    case AxialSkip::ThesisOmegaMax: return "thesis_omega_max";
    case AxialSkip::ThesisOmegaLarge: return "thesis_omega_large";
    case AxialSkip::ThesisOmegaMulti: return "thesis_omega_multi";
  }
  return "?";
}

const std::vector<AxialSkip>& axial_skip_modes() {
  static const std::vector<AxialSkip> modes{AxialSkip::Naive, AxialSkip::Empty, AxialSkip::GlobalMax,
                                            AxialSkip::Omega, AxialSkip::OmegaMulti, AxialSkip::Distance,
                                            AxialSkip::ThesisOmegaMax, AxialSkip::ThesisOmegaLarge,
                                            AxialSkip::ThesisOmegaMulti};
  return modes;
}

AxialSkip parse_axial_skip(const std::string& text, const std::string& option) {
  std::string known;
  for (AxialSkip m : axial_skip_modes()) {
    if (text == to_string(m)) return m;
    known += (known.empty() ? "" : ", ") + std::string(to_string(m));
  }
  throw Error(option + ": '" + text + "' is not a skip mode (known: " + known + ")");
}

AxialSkip effective_skip(const AxialRenderInputs& in) {
  return in.step_aside && in.map->empty_texels == 0 ? AxialSkip::Naive : in.skip;
}

float effective_step(const AxialRenderInputs& in) { return in.step > 0 ? in.step : 0.5f * in.map->texel; }

void validate(const AxialRenderInputs& in) {
  if (!in.map) throw Error("axial render: no map");
  const AxialMap& m = *in.map;
  check_axial_map(m, "axial render: map");
  if (m.height.size() != size_t(m.nx) || m.level_offset.empty())
    throw Error("axial render: map: skip structures missing (call update_skip_structures)");
  if (in.bands.empty() || in.bands.size() > size_t(kMaxBands))
    throw Error("axial render: 1 to " + std::to_string(kMaxBands) + " bands required");
  if (!m.emission.empty() && m.emission.size() != in.bands.size())
    throw Error("axial render: the map has " + std::to_string(m.emission.size()) + " emission planes for " +
                std::to_string(in.bands.size()) + " bands");
  if (!(in.step >= 0.0f) || !std::isfinite(in.step)) throw Error("axial render: step must be finite and >= 0");
  const float h = effective_step(in);
  const double diagonal = std::hypot(double(m.nx), 2.0 * m.nr) * m.texel;
  if (diagonal / h > 1e7) throw Error("axial render: step " + to_text(h) + " gives more than 1e7 samples per ray");
  for (const AxialRenderBand& b : in.bands)
    if (b.albedo > 0 && !in.stars.empty() && !b.table)
      throw Error("axial render: band " + b.name + " scatters but has no table");
  for (size_t k = 0; k < in.stars.size(); ++k) {
    const BakedStar& s = in.stars[k];
    if (s.power.size() != in.bands.size()) throw Error("axial render: star " + std::to_string(k) + " lacks band powers");
    if (!s.depth_v || s.depth_v->size() != m.count())
      throw Error("axial render: star " + std::to_string(k) + " has no baked depth map");
    const Vec3 q = s.position - m.origin;
    const float off = length(q - dot(q, m.axis) * m.axis);
    if (!(off <= 1e-3f * m.texel))
      throw Error("axial render: star " + std::to_string(k) + " lies " + to_text(off) +
                  " from the axis; stars must be on the axis (then their light is axisymmetric)");
  }
  if (in.deform.colour) check_noise(in.deform.colour_noise, false, "axial render: colour deformation");
  if (in.deform.shape) check_noise(in.deform.shape_noise, true, "axial render: shape deformation");
  if (in.diffuse) {
    const DiffuseField& f = *in.diffuse;
    if (f.cells.nz != 1 || f.cells.nx < 1 || f.cells.ny < 1 || !(f.cells.voxel > 0) || f.n_bands() != in.bands.size())
      throw Error("axial render: the diffuse field is not an axial one for these bands (axial/axial_diffuse.h)");
    if (!f.has_harmonics())
      throw Error("axial render: the diffuse field is not packed");
  }
}

Image render_axial_cpu(const AxialRenderInputs& in, AxialRenderStats* stats) {
  HostPlacement host;
  const AxialMarchScene scene = assemble_axial_scene(in, host);
  Image image(in.camera.width, in.camera.height, band_names(in.bands));
  std::atomic<uint64_t> clamps{0}, reads{0};
  const auto start = std::chrono::steady_clock::now();
  dispatch_axial(scene.skip, scene.n_stars > 0, axial_field(scene), in.deform.any(),
                 [&](auto mode, auto has_stars, auto field, auto deform) {
    tbb::parallel_for(tbb::blocked_range<int>(0, in.camera.height), [&](const auto& rows) {
      uint64_t local = 0, local_reads = 0;
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < in.camera.width; ++x) {
          Vec3 origin, dir;
          if (!in.camera.ray(x, y, origin, dir)) continue;
          int visited = 0;
          const RayResult r =
              march_axial_ray<decltype(mode)::value, decltype(has_stars)::value, decltype(field)::value,
                              decltype(deform)::value>(scene, origin, dir, &visited);
          local_reads += uint64_t(visited);
          store_radiance(r, scene.n_bands, in.exposure, image.pixels.data(), image.width, image.height, x, y);
          local += uint64_t(r.table_clamps);
        }
      clamps += local;
      reads += local_reads;
      if (in.progress) in.progress->add(rows.size());
    });
    if constexpr (decltype(has_stars)::value) {
      // The pixels at each star's image, with many rays each (illumination/star_pixels.h).
      if (in.star_pixels)
      march_star_pixels_cpu(in.camera, star_positions(in.stars), scene.n_bands, in.exposure, image.pixels.data(),
                            [&](Vec3 origin, Vec3 dir, float narrowing, float* out, size_t stride) {
                              AxialMarchScene sub = scene;
                              sub.footprint = sub_pixel_footprint(scene.footprint, narrowing);
                              const RayResult r = march_axial_ray<decltype(mode)::value, true, decltype(field)::value,
                                                                  decltype(deform)::value>(sub, origin, dir);
                              for (int b = 0; b < scene.n_bands; ++b) out[size_t(b) * stride] = r.radiance[b];
                              return uint64_t(r.table_clamps);
                            },
                            clamps);
    }
  });
  if (stats) {
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats->table_clamps = clamps;
    stats->samples = reads;
    stats->skip_used = scene.skip;
    stats->device_bytes = host.bytes();
  }
  return image;
}

Image render_axial(const AxialRenderInputs& in, Backend backend, AxialRenderStats* stats) {
  return backend == Backend::Cuda ? render_axial_cuda(in, stats) : render_axial_cpu(in, stats);
}

}  // namespace nebula
