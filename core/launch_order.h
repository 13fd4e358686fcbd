#pragma once
// The order a launch's blocks take their tiles in. A GPU starts a launch's
// blocks in index order, and a frame ends with its slowest rays: started late,
// they make the frame's tail. Marchers whose slowest rays lie around one point
// of the image (a star's image, where the rays shade the most) give the block
// with index j the tile centre_out(j, c, n) per axis, so the tiles around c
// start first and neighbouring blocks still take neighbouring tiles. The
// axial marcher does (H200: its thin map's frame 6% shorter); in the band and
// spectral marchers' launches it measured no gain (docs/performance.md).
#include <optional>
#include <vector>

#include "core/camera.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

// The j-th of c, c - 1, c + 1, c - 2, c + 2, ... over [0, n), the longer side's
// rest after the shorter one ends: a permutation of 0 .. n - 1 for 0 <= c < n
// (c clamped to it).
NEBULA_HD int centre_out(int j, int c, int n) {
  c = c < 0 ? 0 : (c >= n ? n - 1 : c);
  const int below = c, above = n - c;  // tiles below c, and from c up
  const int both = below < above ? below : above;
  if (j < 2 * both) return (j & 1) ? c - (j + 1) / 2 : c + j / 2;
  return above > below ? c + (j - both) : c - (j - both + 1);
}

// A tile of a launch's grid of bx x by pixel tiles.
struct LaunchTile {
  int x = 0, y = 0;
};

// The tile holding the image of the first of `points` (a scene's stars: the
// rays at a star's image shade the most), else the image's centre.
inline LaunchTile first_tile(const Camera& camera, const std::vector<Vec3>& points, int bx, int by) {
  double x = 0.5 * camera.width, y = 0.5 * camera.height;
  if (!points.empty())
    if (const std::optional<ImagePoint> at = project_point(camera, points[0]);
        at && at->x >= 0.0 && at->x < camera.width && at->y >= 0.0 && at->y < camera.height) {
      x = at->x;
      y = at->y;
    }
  return {int(x) / bx, int(y) / by};
}

}  // namespace nebula
