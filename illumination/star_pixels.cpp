#include "illumination/star_pixels.h"

#include <algorithm>
#include <cmath>

namespace nebula {

std::vector<Vec3> star_positions(const std::vector<BakedStar>& stars) {
  std::vector<Vec3> out;
  for (const BakedStar& s : stars) out.push_back(s.position);
  return out;
}

std::vector<StarPixel> star_pixels(const Camera& camera, const std::vector<Vec3>& stars, int* rays) {
  // Per pixel the finest side any star asks for (0: none).
  std::vector<std::pair<int, int>> wanted;  // (pixel index, side)
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
        const double reach = std::max(std::fabs(x + 0.5 - at->x), std::fabs(y + 0.5 - at->y));
        wanted.push_back({y * camera.width + x, reach <= kStarPixelCore ? kStarPixelCoreSide : kStarPixelSide});
      }
  }
  std::sort(wanted.begin(), wanted.end());
  std::vector<StarPixel> out;
  int total = 0;
  for (size_t i = 0; i < wanted.size(); ++i) {
    const bool last_of_pixel = i + 1 == wanted.size() || wanted[i + 1].first != wanted[i].first;
    if (!last_of_pixel) {
      wanted[i + 1].second = std::max(wanted[i + 1].second, wanted[i].second);
      continue;
    }
    StarPixel p;
    p.x = wanted[i].first % camera.width;
    p.y = wanted[i].first / camera.width;
    p.side = wanted[i].second;
    p.first = total;
    total += p.side * p.side;
    out.push_back(p);
  }
  if (rays) *rays = total;
  return out;
}

}  // namespace nebula
