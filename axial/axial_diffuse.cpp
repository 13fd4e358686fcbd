#include "axial/axial_diffuse.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/dda.h"
#include "core/math.h"

namespace nebula {

DensityGrid voxelize_axial_frame(const AxialMap& map, float voxel, std::vector<std::vector<float>>* emission) {
  DensityGrid g;
  const float L = map.length(), R = map.radius();
  g.shape.voxel = voxel;
  g.shape.nx = g.shape.ny = std::max(1, int(std::ceil(2.0f * R / voxel)));
  g.shape.nz = std::max(1, int(std::ceil(L / voxel)));
  g.shape.origin = {-0.5f * voxel * g.shape.nx, -0.5f * voxel * g.shape.ny, 0.0f};
  g.tau_v.assign(g.shape.count(), 0.0f);
  const size_t planes = emission ? map.emission.size() : 0;
  if (emission) emission->assign(planes, std::vector<float>(g.shape.count(), 0.0f));
  const int s = std::clamp(int(std::ceil(2.0f * voxel / map.texel - 1e-4f)), 1, 4);
  const float rescale = voxel / map.texel / float(s * s * s);  // the mean, per voxel edge
  const float inv_texel = 1.0f / map.texel;
  // The texel row (r) of each point of a column's cross-section and the
  // texel column (x) of each point along z: every point is one of each.
  std::vector<int> x_of(size_t(g.shape.nz) * s);
  for (size_t k = 0; k < x_of.size(); ++k) {
    const float fx = std::floor((k + 0.5f) / s * voxel * inv_texel);
    x_of[k] = fx < map.nx ? int(fx) : -1;
  }
  tbb::parallel_for(0, g.shape.ny, [&](int y) {
    std::vector<int> r_of;
    std::vector<double> sum(1 + planes);
    for (int x = 0; x < g.shape.nx; ++x) {
      r_of.clear();
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
          const float px = g.shape.origin.x + voxel * (x + (i + 0.5f) / s),
                      py = g.shape.origin.y + voxel * (y + (j + 0.5f) / s);
          const float fr = std::floor(std::hypot(px, py) * inv_texel);
          if (fr < map.nr) r_of.push_back(int(fr));
        }
      if (r_of.empty()) continue;
      for (int z = 0; z < g.shape.nz; ++z) {
        std::fill(sum.begin(), sum.end(), 0.0);
        for (int k = 0; k < s; ++k) {
          const int ix = x_of[size_t(z) * s + k];
          if (ix < 0) continue;
          for (int ir : r_of) {
            const size_t t = map.index(ix, ir);
            sum[0] += map.tau_v[t];
            for (size_t b = 0; b < planes; ++b) sum[1 + b] += map.emission[b][t];
          }
        }
        const size_t v = g.shape.index(x, y, z);
        g.tau_v[v] = float(sum[0]) * rescale;
        for (size_t b = 0; b < planes; ++b) (*emission)[b][v] = float(sum[1 + b]) * rescale;
      }
    }
  });
  return g;
}

namespace {

// The 3D field's harmonics averaged over the ring of 2D cell (cx, cr): points
// on a 2 x 2 grid in (x, r) and enough azimuths to visit every 3D cell the
// ring crosses twice, weighted by r (the ring's volume), each turned into its
// meridian's frame. The zonal blocks after the harmonics (degrees about the
// line from a star on the axis: the same in every meridian) are averaged as
// they are.
void ring_average(const DiffuseField& f3, const std::vector<float>& c3, int cx, int cr, float edge, float* out) {
  const int n = f3.n_coeffs();
  const GridShape& c = f3.cells;
  std::fill(out, out + n, 0.0f);
  std::vector<double> sum(static_cast<size_t>(n), 0.0);  // harmonics, then zonal blocks: more than kMaxShCoeffs
  std::vector<float> turned(static_cast<size_t>(n));
  double weight = 0;
  constexpr int kSub = 2;
  for (int j = 0; j < kSub; ++j) {
    const float r = (cr + (j + 0.5f) / kSub) * edge;
    const int n_phi = std::max(16, int(std::ceil(4.0f * kPi * r / edge)));
    for (int i = 0; i < kSub; ++i) {
      const float x = (cx + (i + 0.5f) / kSub) * edge;
      for (int k = 0; k < n_phi; ++k) {
        const float phi = 2.0f * kPi * (k + 0.5f) / n_phi, cp = std::cos(phi), sp = std::sin(phi);
        const Vec3 p{r * cp, r * sp, x};
        int ijk[3];
        const int dims[3] = {c.nx, c.ny, c.nz};
        for (int a = 0; a < 3; ++a)
          ijk[a] = std::clamp(int(std::floor((detail::axis(p, a) - detail::axis(c.origin, a)) / c.voxel)), 0, dims[a] - 1);
        const float* from = &c3[c.index(ijk[0], ijk[1], ijk[2]) * size_t(n)];
        sh_rotate_z(f3.degree, cp, sp, from, turned.data());
        for (int q = sh_count(f3.degree); q < n; ++q) turned[q] = from[q];
        const double w = r / n_phi;
        for (int q = 0; q < n; ++q) sum[q] += w * turned[q];
        weight += w;
      }
    }
  }
  for (int q = 0; q < n; ++q) out[q] = float(sum[q] / weight);
}

}  // namespace

DiffuseField bake_axial_diffuse(const AxialMap& map, const std::vector<DiffuseBand>& bands,
                                const std::vector<StarLight>& stars, const DiffuseBakeOptions& options,
                                Backend backend, AxialDiffuseStats* stats, Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  check_axial_map(map, "axial diffuse bake: map");
  if (options.cells < 1 || options.cells > 4096)
    throw ParameterError("diffuse_cells", "must be 1 to 4096, got " + std::to_string(options.cells));
  // Photons in the map's frame: the axis is z, star k at (0, 0, x_k).
  std::vector<StarLight> local = stars;
  for (size_t k = 0; k < stars.size(); ++k) {
    const Vec3 q = stars[k].position - map.origin;
    const float x = dot(q, map.axis);
    const float off = length(q - x * map.axis);
    if (!(off <= 1e-3f * map.texel))
      throw Error("axial diffuse bake: star " + std::to_string(k) + " lies " + to_text(off) +
                  " from the axis; stars must be on the axis (then the field is axisymmetric)");
    local[k].position = {0.0f, 0.0f, x};
  }
  const float longest = std::max(map.length(), 2.0f * map.radius());
  const float voxel = std::max(map.texel, longest / float(2 * options.cells));
  const DensityGrid grid = voxelize_axial_frame(map, voxel);
  AxialDiffuseStats st;
  st.grid = grid.shape;
  const DiffuseField f3 = bake_diffuse(grid, bands, local, options, backend, &st.bake, progress);

  DiffuseField f;
  f.degree = f3.degree;
  f.zonal = f3.zonal;
  f.zonal_stars = f3.zonal_stars;
  for (int k = 0; k < f3.zonal_stars; ++k) f.zonal_star[k] = map.origin + f3.zonal_star[k].z * map.axis;  // back to the world
  f.shift = 0;
  const float edge = f3.cells.voxel;
  f.cells.voxel = edge;
  f.cells.origin = {0.0f, 0.0f, 0.0f};
  f.cells.nx = std::max(1, int(std::ceil(map.length() / edge - 1e-4f)));
  f.cells.ny = std::max(1, int(std::ceil(map.radius() / edge - 1e-4f)));
  f.cells.nz = 1;
  const int n = f.n_coeffs();
  f.allocate(f3.n_bands());
  f.response = f3.response;
  f.response_tau_max = f3.response_tau_max;
  for (size_t b = 0; b < f3.n_bands(); ++b) {
    if (!f3.has_band(b)) continue;
    const std::vector<float> c3 = f3.band_coeffs(b);
    std::vector<float> c(f.cells.count() * size_t(n), 0.0f);
    tbb::parallel_for(0, f.cells.ny, [&](int cr) {
      for (int cx = 0; cx < f.cells.nx; ++cx)
        ring_average(f3, c3, cx, cr, edge, &c[f.cells.index(cx, cr, 0) * size_t(n)]);
    });
    f.set_band_coeffs(b, c);
  }
  st.bake.field_bytes = f.bytes();
  st.bake.work_bytes += f3.bytes() + grid.tau_v.size() * sizeof(float);
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = st;
  return f;
}

}  // namespace nebula
