#pragma once
// The order a launch's blocks take their tiles in. A GPU starts a launch's
// blocks in index order, and a frame ends with its slowest rays: started late,
// they make the frame's tail. Marchers whose slowest rays lie around one point
// of the image (a star's image, where the rays shade the most) give the block
// with index j the tile centre_out(j, c, n) per axis, so the tiles around c
// start first and neighbouring blocks still take neighbouring tiles.
#include "core/hd.h"

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

}  // namespace nebula
