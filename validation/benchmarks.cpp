#include "validation/benchmarks.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "axial/axial_bake.h"
#include "axial/axial_diffuse.h"
#include "axial/axial_renderer.h"
#include "core/philox.h"
#include "illumination/optical_depth_bake.h"
#include "montecarlo/table_conversion.h"
#include "multires/pyramid_render.h"
#include "raycast/renderer.h"
#include "scene/density_sources.h"
#include "tables/scattering_table.h"
#include "truth/truth_renderer.h"

namespace nebula {
namespace {

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

ThroughputResult bench_throughput(Backend backend, const TabulateParams& p, int repeats) {
  ThroughputResult r;
  r.backend = to_string(backend);
  r.params = p;
  r.repeats = repeats;
  tabulate(p, backend);  // warm-up: context creation, module load, thread pool
  std::vector<double> compute, wall;
  uint64_t events = 0;
  for (int i = 0; i < repeats; ++i) {
    const Tabulation t = tabulate(p, backend);
    compute.push_back(t.compute_seconds);
    wall.push_back(t.seconds);
    events = t.scattering_events;
    r.device = t.device;
  }
  r.median_seconds = median_of(compute);
  r.median_wall = median_of(wall);
  const double photons = double(photons_of_table(p));
  r.photons_per_second = photons / r.median_seconds;
  r.events_per_second = double(events) / r.median_seconds;
  r.events_per_photon = double(events) / photons;
  return r;
}

std::vector<ConvergenceRow> bench_convergence(Backend backend, const TabulateParams& base,
                                              const std::vector<uint64_t>& counts, int ref_factor) {
  TabulateParams ref_params = base;
  ref_params.photons_per_row =
      std::min<uint64_t>(*std::max_element(counts.begin(), counts.end()) * ref_factor,
                        kMaxPhotonsPerRow / uint64_t(base.thin_boost));
  ref_params.seed = base.seed + 1000003;  // independent of every run below
  const Tabulation ref = tabulate(ref_params, backend);
  double ref_norm = 0;
  for (double v : ref.P) ref_norm += v * v;
  ref_norm = std::sqrt(ref_norm);
  std::vector<ConvergenceRow> rows;
  for (uint64_t n : counts) {
    TabulateParams p = base;
    p.photons_per_row = n;
    const Tabulation t = tabulate(p, backend);
    ConvergenceRow row;
    row.photons_per_row = n;
    row.seconds = t.compute_seconds;
    double err2 = 0, pred2 = 0, z2 = 0;
    size_t nz = 0;
    for (size_t e = 0; e < t.P.size(); ++e) {
      const double d = t.P[e] - ref.P[e];
      const double s2 = t.P_stderr[e] * t.P_stderr[e] + ref.P_stderr[e] * ref.P_stderr[e];
      err2 += d * d;
      pred2 += s2;
      if (s2 > 0) {
        z2 += d * d / s2;
        ++nz;
      }
    }
    row.rel_l2_error = std::sqrt(err2) / ref_norm;
    row.predicted = std::sqrt(pred2) / ref_norm;
    row.rms_z = nz ? std::sqrt(z2 / nz) : 0;
    rows.push_back(row);
  }
  return rows;
}

BakeBenchResult bench_bake(Backend backend, int size, int stars, int repeats) {
  DensityGrid grid;
  grid.shape.nx = grid.shape.ny = grid.shape.nz = size;
  grid.tau_v.resize(grid.shape.count());
  for (size_t c = 0; c < grid.tau_v.size(); ++c)
    grid.tau_v[c] = 2.0f * philox_uniform4(31, 0, uint32_t(c), 0, 0).u0;
  std::vector<Vec3> positions;
  for (int s = 0; s < stars; ++s) {
    const float f = float(size);
    positions.push_back(s == 0 ? Vec3{0.45f * f, 0.52f * f, 0.47f * f}
                               : Vec3{-0.5f * f * s, 0.3f * f, 1.2f * f});
  }
  BakeBenchResult r;
  r.backend = to_string(backend);
  r.size = size;
  r.stars = stars;
  r.repeats = repeats;
  bake_star_depths(grid, positions, backend);  // warm-up
  std::vector<double> times;
  for (int i = 0; i < repeats; ++i) times.push_back(bake_star_depths(grid, positions, backend).seconds);
  r.median_seconds = median_of(times);
  r.voxels_per_second = double(grid.shape.count()) * stars / r.median_seconds;
  return r;
}

namespace {

// The procedural nebula of the 2005 paper's section 4.3 (scene/), its
// default parameters at size^3 voxels over a 2 pc cube, a table tabulated on
// the same backend (a = g = 0.6, 10^4 photons per row) and a perspective
// camera outside the cloud.
struct BenchNebula {
  DensityGrid grid;
  Vec3 centre;
  ScatteringTable table;
  CameraSettings camera;
  // with_table: also tabulate the table (the path tracer needs none).
  BenchNebula(Backend backend, int size, int width, int height, bool with_table = true) {
    ProceduralParams pp;
    pp.n = size;
    grid = procedural_nebula(pp);
    centre = procedural_star_position(pp);
    if (with_table) {
      TabulateParams tp;
      tp.photons_per_row = 10000;
      tp.binning = AngularBinning::UniformTheta;
      table = to_table(tabulate(tp, backend));
    }
    camera.position = centre + Vec3{0.4f, -3.2f, 1.1f};
    camera.look_at = centre;
    camera.up = {0, 0, 1};
    camera.fov_deg = 45;
    camera.width = width;
    camera.height = height;
  }
  // Star k: the first at the nebula's star, the others around it.
  Vec3 star(int k) const {
    return k == 0 ? centre : centre + Vec3{0.5f * std::cos(1.3f * k), 0.5f * std::sin(1.3f * k), 0.1f * k - 0.4f};
  }
  RenderInputs inputs(const std::vector<Vec3>& positions, const BakeResult& bake) const {
    RenderInputs in;
    in.density = &grid;
    const float ratios[3] = {1.2f, 1.0f, 0.85f};
    for (int b = 0; b < 3; ++b) in.bands.push_back(RenderBand{{std::string(1, "BVR"[b]), ratios[b], 0.6f}, &table, nullptr});
    for (size_t k = 0; k < positions.size(); ++k)
      in.stars.push_back(BakedStar{{positions[k], {1e3f, 1e3f, 1e3f}}, &bake.tau_v[k]});
    in.camera = make_camera(camera);
    return in;
  }
};

}  // namespace

std::vector<RenderBenchRow> bench_render(Backend backend, int size, int width, int height, int max_stars,
                                         int repeats) {
  const BenchNebula nebula(backend, size, width, height);
  std::vector<RenderBenchRow> rows;
  for (int stars = 1; stars <= max_stars; stars *= 2) {
    std::vector<Vec3> positions;
    for (int k = 0; k < stars; ++k) positions.push_back(nebula.star(k));
    const BakeResult bake = bake_star_depths(nebula.grid, positions, backend);
    const RenderInputs in = nebula.inputs(positions, bake);
    RenderStats stats;
    render(in, backend, &stats);  // warm-up
    std::vector<double> times;
    for (int i = 0; i < repeats; ++i) {
      render(in, backend, &stats);
      times.push_back(stats.seconds);
    }
    RenderBenchRow row;
    row.backend = to_string(backend);
    row.width = width;
    row.height = height;
    row.size = size;
    row.stars = stars;
    row.median_seconds = median_of(times);
    row.rays_per_second = double(width) * height / row.median_seconds;
    rows.push_back(row);
  }
  return rows;
}

DiffuseBench bench_diffuse(Backend backend, int size, int width, int height, int repeats, int degree, int cells,
                           uint64_t photons, int zonal, bool star_pixels) {
  const BenchNebula nebula(backend, size, width, height);
  const std::vector<Vec3> positions{nebula.star(0)};
  DiffuseBench out;
  out.backend = to_string(backend);
  out.size = size;
  out.width = width;
  out.height = height;
  out.degree = degree;
  out.photons = photons;
  BakeResult bake = bake_star_depths(nebula.grid, positions, backend);  // warm-up
  RenderInputs in = nebula.inputs(positions, bake);
  in.star_pixels = star_pixels;
  std::vector<DiffuseBand> bands;
  for (const RenderBand& b : in.bands) {
    DiffuseBand d;
    static_cast<Band&>(d) = b;
    d.table = b.table;
    bands.push_back(d);
  }
  std::vector<StarLight> stars;
  for (const BakedStar& s : in.stars) stars.push_back(s);
  DiffuseBakeOptions o;
  o.degree = degree;
  o.zonal = zonal;
  o.cells = cells;
  o.photons = photons;
  DiffuseBakeStats stats;
  DiffuseField field = bake_diffuse(nebula.grid, bands, stars, o, backend, &stats);  // warm-up
  std::vector<double> star_times, photon_times, wall_times;
  for (int i = 0; i < repeats; ++i) {
    star_times.push_back(bake_star_depths(nebula.grid, positions, backend).seconds);
    const auto t0 = std::chrono::steady_clock::now();
    field = bake_diffuse(nebula.grid, bands, stars, o, backend, &stats);
    wall_times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    photon_times.push_back(stats.seconds);
  }
  out.star_bake_seconds = median_of(star_times);
  out.photon_seconds = median_of(photon_times);
  out.bake_wall_seconds = median_of(wall_times);
  out.cells = field.cells.nx;
  out.field_bytes = stats.field_bytes;
  out.work_bytes = stats.work_bytes;
  out.star_depth_bytes = nebula.grid.tau_v.size() * sizeof(float);
  out.noise = stats.noise[1];
  RenderInputs without = in, with = in;
  with.diffuse = &field;
  for (RenderInputs* frame : {&without, &with}) {
    RenderStats rs;
    render(*frame, backend, &rs);  // warm-up
    std::vector<double> times;
    for (int i = 0; i < repeats; ++i) {
      render(*frame, backend, &rs);
      times.push_back(rs.seconds);
    }
    (frame == &with ? out.frame_with : out.frame_without) = median_of(times);
  }
  return out;
}

PyramidBench bench_pyramid(Backend backend, int size, int width, int height, int levels, int repeats) {
  const BenchNebula nebula(backend, size, width, height);
  const std::vector<Vec3> positions{nebula.star(0)};
  const BakeResult bake = bake_star_depths(nebula.grid, positions, backend);
  const RenderInputs in = nebula.inputs(positions, bake);
  PyramidBench out;
  out.backend = to_string(backend);
  out.size = size;
  out.bake_seconds = bake.seconds;
  const PreparedPyramid prepared = prepare_pyramid(in, levels, backend);
  render_pyramid(in, prepared, backend);  // warm-up
  std::vector<std::vector<double>> render_times(levels + 1);
  std::vector<double> combine_times;
  for (int i = 0; i < repeats; ++i) {
    const PyramidResult r = render_pyramid(in, prepared, backend);
    for (int j = 0; j <= levels; ++j) render_times[j].push_back(r.report[j].render_seconds);
    combine_times.push_back(r.combine_seconds);
    if (i == 0) out.levels = r.report;
  }
  for (int j = 0; j <= levels; ++j) out.levels[j].render_seconds = median_of(render_times[j]);
  out.combine_seconds = median_of(combine_times);
  return out;
}

}  // namespace nebula

namespace nebula {

TruthBenchRow bench_truth(Backend backend, int size, int width, int height, int spp, int repeats,
                          bool exact_transmittance, bool equiangular, int threads_per_pixel) {
  const BenchNebula nebula(backend, size, width, height, false);
  TruthInputs in;
  in.density = &nebula.grid;
  const float ratios[3] = {1.2f, 1.0f, 0.85f};
  for (int b = 0; b < 3; ++b) in.bands.push_back(TruthBand{{std::string(1, "BVR"[b]), ratios[b], 0.6f, 0.6f}, nullptr});
  in.stars = {StarLight{nebula.centre, {1e3f, 1e3f, 1e3f}}};
  in.camera = make_camera(nebula.camera);
  in.spp = spp;
  in.exact_transmittance = exact_transmittance;
  in.equiangular = equiangular;
  in.gpu_threads_per_pixel = threads_per_pixel;
  TruthOutput out = render_truth(in, backend);  // warm-up
  std::vector<double> times;
  for (int i = 0; i < repeats; ++i) {
    in.seed = 2 + i;
    out = render_truth(in, backend);
    times.push_back(out.seconds);
  }
  TruthBenchRow row;
  row.backend = to_string(backend);
  row.width = width;
  row.height = height;
  row.size = size;
  row.spp = spp;
  row.median_seconds = median_of(times);
  row.vertices_per_second = out.counters.vertices / row.median_seconds;
  row.paths_per_second = out.paths / row.median_seconds;
  row.spp_per_second = spp / row.median_seconds;
  row.vertices_per_path = out.paths ? double(out.counters.vertices) / out.paths : 0;
  row.threads_per_pixel = out.threads_per_pixel;
  return row;
}

void bench_axial(Backend backend, int map_size, int width, int height, int repeats, float step_texels,
                 const std::vector<std::string>& maps, const std::vector<int>& inclinations, bool star,
                 const std::function<void(const AxialBenchRow&)>& on_row, bool step_aside,
                 std::vector<AxialSkip> modes, bool diffuse, const std::vector<AxialDeformSettings>& deforms,
                 bool star_pixels) {
  if (modes.empty()) modes = axial_skip_modes();
  modes.erase(std::remove(modes.begin(), modes.end(), AxialSkip::Naive), modes.end());
  modes.insert(modes.begin(), AxialSkip::Naive);
  ScatteringTable table;
  if (star) {
    TabulateParams tp;
    tp.photons_per_row = 2000;  // the table's values do not change the timing
    tp.binning = AngularBinning::UniformTheta;
    table = to_table(tabulate(tp, backend));
  }
  const float texel = 1.0f / map_size;
  for (const std::string& name : maps) {
    AxialMap map = synthetic_axial_map(name, map_size, map_size, texel, 3, 2.0f);
    map.origin = {0, 0, -0.5f};
    map.axis = {0, 0, 1};
    const Vec3 centre{0, 0, 0};
    std::vector<std::vector<float>> depth;
    AxialRenderInputs in;
    in.map = &map;
    in.star_pixels = star_pixels;
    const float ratios[3] = {1.2f, 1.0f, 0.85f};
    for (int b = 0; b < 3; ++b)
      in.bands.push_back(AxialRenderBand{{std::string(1, "BVR"[b]), ratios[b], star ? 0.6f : 0.0f}, star ? &table : nullptr});
    if (star) {
      depth = bake_axial_star_depths(map.nx, map.nr, map.texel, map.tau_v, {0.5f}, backend).tau_v;
      in.stars.push_back(BakedStar{{centre, {1.0f, 1.0f, 1.0f}}, &depth[0]});
    }
    DiffuseField field;
    double bake_ms = 0;
    if (star && diffuse) {
      std::vector<DiffuseBand> bands;
      for (const AxialRenderBand& b : in.bands) {
        DiffuseBand d;
        static_cast<Band&>(d) = b;
        d.table = &table;
        bands.push_back(d);
      }
      const auto t0 = std::chrono::steady_clock::now();
      DiffuseBakeOptions options;
      options.degree = 4;  // a scene's "auto" for this table's g (0.6; scene/scene.cpp, resolved_order)
      field = bake_axial_diffuse(map, bands, {static_cast<const StarLight&>(in.stars[0])}, options, backend);
      bake_ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      in.diffuse = &field;
    }
    in.step = step_texels * texel;
    in.step_aside = step_aside;
    const double empty_fraction = double(map.empty_texels) / double(map.count());
    for (const AxialDeformSettings& deform : deforms)
    for (int inc : inclinations) {
      in.deform = deform;
      const double i = inc * kPiD / 180.0;
      CameraSettings cs;
      cs.projection = Projection::Orthographic;
      const Vec3 from{float(std::sin(i)), 0.0f, float(std::cos(i))};
      cs.position = centre + 4.0f * from;
      cs.look_at = centre;
      cs.up = inc == 0 ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
      // The map's silhouette: a 1 x 2 rectangle seen at inclination i.
      cs.ortho_width = 2.05;
      cs.width = width;
      cs.height = height;
      in.camera = make_camera(cs);
      Image naive;
      double naive_ms = 0;
      for (AxialSkip mode : modes) {
        in.skip = mode;
        AxialRenderStats stats;
        Image image = render_axial(in, backend, &stats);  // warm-up
        std::vector<double> times;
        for (int r = 0; r < repeats; ++r) {
          image = render_axial(in, backend, &stats);
          times.push_back(stats.seconds);
        }
        AxialBenchRow row;
        row.backend = to_string(backend);
        row.map = name;
        row.mode = to_string(mode);
        row.map_size = map_size;
        row.width = width;
        row.height = height;
        row.inclination_deg = inc;
        row.median_ms = 1e3 * median_of(times);
        row.samples = stats.samples;
        row.diffuse_bake_ms = bake_ms;
        row.ran = to_string(stats.skip_used);
        row.deformed = deform.any();
        row.empty_fraction = empty_fraction;
        if (mode == AxialSkip::Naive) {
          naive = image;
          naive_ms = row.median_ms;
        }
        row.speedup = naive_ms / row.median_ms;
        double peak = 0, worst = 0;
        for (size_t p = 0; p < image.pixels.size(); ++p) {
          peak = std::max(peak, double(std::fabs(naive.pixels[p])));
          worst = std::max(worst, double(std::fabs(image.pixels[p] - naive.pixels[p])));
        }
        row.max_difference = peak > 0 ? worst / peak : worst;
        on_row(row);
      }
    }
  }
}

AxialDeformSettings bench_axial_deformations(NoiseKind kind) {
  AxialDeformSettings d;
  d.colour = d.shape = true;
  d.colour_noise.kind = d.shape_noise.kind = kind;
  d.colour_noise.amplitude = 0.5f;
  d.shape_noise.amplitude = 0.2f;
  d.shape_noise.seed = 2;
  return d;
}

}  // namespace nebula
