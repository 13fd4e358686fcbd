#pragma once
// The pixels around a star's image, where one ray cannot stand for its pixel.
// A star inside dust lights the pixels at its image with light that changes
// within each of them: 1/b from the star (b the distance from it), and with
// forward scattering the phase's peak, seen from the star under angles b/s
// that a single ray per pixel samples at one b only (on axial_lopsided at
// g = 0.9 one ray per pixel left the four pixels at the star 0.57 of their
// area's mean). These pixels are cut into square cells, finer towards the
// star's image (a quadtree: a cell is split while a star's image is nearer
// than kStarCellSplit of its sides), and each cell is marched with side x
// side stratified rays, each standing for its own sub-cell (a footprint
// narrower by side / the cell's size); the pixel is the area-weighted mean,
// summed in a fixed order: on the CPU and the GPU the same sums. The band,
// axial and spectral marchers all do it (docs/marcher.md, "The star's own
// pixels").
#include <vector>

#include "core/bands.h"
#include "core/camera.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

// The pixels whose centre lies within kStarPixelReach pixels of a star's
// image (per axis) are star pixels.
constexpr float kStarPixelReach = 3.0f;
// A cell is split in four while a star's image lies nearer to it than
// kStarCellSplit of its sides (0 inside it), down to cells of kStarCellFinest
// pixels.
constexpr float kStarCellSplit = 1.0f, kStarCellFinest = 1.0f / 64.0f;
// Rays per side in a cell at distance d from the nearest star's image:
// K / (1 + d / size) rounded up, K = kStarPixelRays for a pixel left whole and
// kStarCellRays for a part of one (its error weighs by its area); cells of the
// finest size take kStarFinestCellSide. Chosen on axial_lopsided (g = 0, 0.6,
// 0.9; the star on a pixel corner, a centre and elsewhere) against 192 x 192
// rays per pixel: docs/marcher.md, "The star's own pixels".
constexpr float kStarPixelRays = 20.0f, kStarCellRays = 12.0f;
constexpr int kStarFinestCellSide = 4;

// One square cell of a star pixel; a pixel's cells tile it, listed together.
struct StarPixel {
  int x = 0, y = 0;    // the pixel
  float u = 0, v = 0;  // the cell's corner within the pixel, in pixel widths
  float size = 1;      // the cell's side, in pixel widths
  int side = 1;        // rays per side of the cell
  int first = 0;       // its first ray among all cells' rays
  int cells = 0;       // on a pixel's first cell, how many cells the pixel has; 0 on the others
};

// The stars' positions.
std::vector<Vec3> star_positions(const std::vector<BakedStar>& stars);

// The cells of the star pixels of `camera` for stars at these positions (each
// pixel once, row by row, its cells together), their rays numbered
// consecutively; `rays` gets their total.
std::vector<StarPixel> star_pixels(const Camera& camera, const std::vector<Vec3>& stars, int* rays);

// How many star pixels, cells and rays star_pixels gives (for run reports).
struct StarPixelCount {
  int pixels = 0, cells = 0, rays = 0;
};
StarPixelCount count_star_pixels(const Camera& camera, const std::vector<Vec3>& stars);

// Ray k (0 <= k < side^2) of a cell: the centre of its stratum.
NEBULA_HD bool star_pixel_ray(const Camera& c, const StarPixel& p, int k, Vec3& origin, Vec3& dir) {
  const float step = p.size / float(p.side);
  return c.ray_through(float(p.x) + p.u + (float(k % p.side) + 0.5f) * step,
                       float(p.y) + p.v + (float(k / p.side) + 0.5f) * step, origin, dir);
}

// How many times narrower than its pixel a ray of this cell is.
NEBULA_HD float star_pixel_narrowing(const StarPixel& p) { return float(p.side) / p.size; }

// A sub-pixel's footprint: `narrowing` times narrower than the pixel's.
NEBULA_HD RayFootprint sub_pixel_footprint(RayFootprint f, float narrowing) {
  f.width_at_eye /= narrowing;
  f.spread /= narrowing;
  return f;
}

// The cell that ray i (0 <= i < total) belongs to: binary search on `first`.
NEBULA_HD int star_pixel_of_ray(const StarPixel* pixels, int n, int i) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (pixels[mid].first <= i) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

// Ray i (0 <= i < rays) of the star pixels' cells `list` (n of them):
// march(origin, dir, narrowing, out, stride) marches it as a sub-pixel
// `narrowing` times narrower than its pixel, writes its n_planes values to
// out[b * stride] and returns its table clamps; here out = sub + i, stride =
// rays. A ray the camera cannot trace (outside a fisheye's dome) gives zeros.
// The marchers' CPU loops and CUDA kernels all call this.
template <class March>
NEBULA_HD int march_star_pixel_ray(const Camera& camera, const StarPixel* list, int n, int rays, int i, int n_planes,
                                   float* sub, March march) {
  const StarPixel& p = list[star_pixel_of_ray(list, n, i)];
  float* out = sub + i;
  Vec3 origin, dir;
  if (!star_pixel_ray(camera, p, i - p.first, origin, dir)) {
    for (int b = 0; b < n_planes; ++b) out[size_t(b) * rays] = 0.0f;
    return 0;
  }
  return int(march(origin, dir, star_pixel_narrowing(p), out, size_t(rays)));
}

// Storing the star pixels takes two steps, each over every (cell, plane),
// so that no thread sums a whole pixel's rays (a GPU thread doing that for
// every plane of a spectral image took 0.1-0.17 ms): first each cell's rays'
// mean, summed in their order and written over the cell's first ray value
// (sub: plane b of ray j at sub[b * rays + j]; the cells' rays do not
// overlap); then each pixel from its cells.
NEBULA_HD void reduce_star_cell(float* sub, size_t rays, const StarPixel* list, int c, int b) {
  const StarPixel& cell = list[c];
  const int n = cell.side * cell.side;
  float* values = sub + size_t(b) * rays + size_t(cell.first);
  float sum = 0.0f;
  for (int k = 0; k < n; ++k) sum += values[k];
  values[0] = sum / float(n);
}

// The second step, after every cell's first: plane b of a star pixel,
// stored by its first cell list[i] (the other cells do nothing), its cells'
// means weighted by their areas in their order, times the exposure, stored as
// a ray's value is ([plane][y][x]).
NEBULA_HD void store_star_pixel(const float* sub, size_t rays, const StarPixel* list, int i, int b, float exposure,
                                float* pixels, int width, int height) {
  const StarPixel& p = list[i];
  if (p.cells == 0) return;
  float pixel = 0.0f;
  for (int c = i; c < i + p.cells; ++c) {
    const StarPixel& cell = list[c];
    pixel += (cell.size * cell.size) * sub[size_t(b) * rays + size_t(cell.first)];
  }
  pixels[size_t(b) * width * height + size_t(p.y) * width + p.x] = exposure * pixel;
}

}  // namespace nebula
