#include "illumination/star_pixels.h"

#include <algorithm>
#include <cmath>

namespace nebula {
namespace {

struct Point2 {
  double x, y;
};

// Distance from point s to the square [u, u + size] x [v, v + size].
double distance_to_cell(Point2 s, double u, double v, double size) {
  const double dx = std::max({u - s.x, 0.0, s.x - (u + size)});
  const double dy = std::max({v - s.y, 0.0, s.y - (v + size)});
  return std::sqrt(dx * dx + dy * dy);
}

// The cells of one pixel (stars: the stars' images in its own coordinates,
// the pixel being [0, 1]^2), depth first, the four children in row order.
void add_cells(const std::vector<Point2>& stars, double u, double v, double size, StarPixel pixel,
               std::vector<StarPixel>& out, int& rays) {
  double d = INFINITY;
  for (const Point2& s : stars) d = std::min(d, distance_to_cell(s, u, v, size));
  if (d < kStarCellSplit * size && size > 1.5 * kStarCellFinest) {
    const double h = 0.5 * size;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) add_cells(stars, u + i * h, v + j * h, h, pixel, out, rays);
    return;
  }
  pixel.u = float(u);
  pixel.v = float(v);
  pixel.size = float(size);
  const double k = size >= 1.0 ? kStarPixelRays : kStarCellRays;
  pixel.side = size < 1.5 * kStarCellFinest ? kStarFinestCellSide : int(std::ceil(k / (1.0 + d / size) - 1e-9));
  pixel.first = rays;
  pixel.cells = 0;
  rays += pixel.side * pixel.side;
  out.push_back(pixel);
}

}  // namespace

std::vector<Vec3> star_positions(const std::vector<BakedStar>& stars) {
  std::vector<Vec3> out;
  for (const BakedStar& s : stars) out.push_back(s.position);
  return out;
}

std::vector<StarPixel> star_pixels(const Camera& camera, const std::vector<Vec3>& stars, int* rays) {
  // Per pixel, the images of the stars that reach it.
  std::vector<std::pair<int, Point2>> wanted;  // (pixel index, star image in image coordinates)
  for (const Vec3& star : stars) {
    const std::optional<ImagePoint> at = project_point(camera, star);
    if (!at) continue;
    const int x0 = std::max(0, int(std::ceil(at->x - 0.5 - kStarPixelReach)));
    const int x1 = std::min(camera.width - 1, int(std::floor(at->x - 0.5 + kStarPixelReach)));
    const int y0 = std::max(0, int(std::ceil(at->y - 0.5 - kStarPixelReach)));
    const int y1 = std::min(camera.height - 1, int(std::floor(at->y - 0.5 + kStarPixelReach)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        Vec3 o, d;
        if (!camera.ray(x, y, o, d)) continue;  // a fisheye pixel outside the dome
        wanted.push_back({y * camera.width + x, Point2{at->x, at->y}});
      }
  }
  std::stable_sort(wanted.begin(), wanted.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<StarPixel> out;
  int total = 0;
  for (size_t i = 0; i < wanted.size();) {
    size_t end = i;
    StarPixel p;
    p.x = wanted[i].first % camera.width;
    p.y = wanted[i].first / camera.width;
    std::vector<Point2> local;
    for (; end < wanted.size() && wanted[end].first == wanted[i].first; ++end)
      local.push_back({wanted[end].second.x - p.x, wanted[end].second.y - p.y});
    const size_t start = out.size();
    add_cells(local, 0.0, 0.0, 1.0, p, out, total);
    out[start].cells = int(out.size() - start);
    i = end;
  }
  if (rays) *rays = total;
  return out;
}

StarPixelCount count_star_pixels(const Camera& camera, const std::vector<Vec3>& stars) {
  StarPixelCount n;
  const std::vector<StarPixel> cells = star_pixels(camera, stars, &n.rays);
  n.cells = int(cells.size());
  for (const StarPixel& c : cells) n.pixels += c.cells > 0;
  return n;
}

}  // namespace nebula
