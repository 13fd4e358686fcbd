#pragma once
// The image side of the pyramid (2005 paper, section 4.2): level j is
// rendered from volume level j at 1/2^j of the resolution (image size
// ceil(W / 2^j) x ceil(H / 2^j), a coarse pixel spanning 2x2 pixels of the
// level below). The difference images dI_j = I_j - down(I_{j-1}), clipped at
// 0, hold the light that only the coarser voxels' wider multiple scattering
// adds; summed from the coarsest level up and added to I_0 they never take
// light away.
#include <vector>

#include "core/image.h"

namespace nebula {

// Size of the image one level coarser: ceil(n / 2).
int coarser_size(int n);

// 2x2 box mean onto a (width, height) = (ceil(w/2), ceil(h/2)) image; at odd
// edges the mean of the pixels that exist.
Image downsample_2x(const Image& fine);

// Bilinear interpolation at the centres of a (width, height) image one level
// finer (coarse pixel i covers fine pixels 2i and 2i + 1); clamped at the
// edges. Never negative where the input is not.
Image upsample_2x(const Image& coarse, int width, int height);

// max(I_j - down(I_{j-1}), 0) per band and pixel.
Image clipped_difference(const Image& coarse, const Image& finer);

// levels[0] is I_0 at full size, levels[j] is I_j. Returns
// I_0 + up(dI_1 + up(dI_2 + ... up(dI_n))). One image: a copy of it.
// `differences`, if given, receives dI_1..dI_n (index 0 is left empty).
Image combine_pyramid(const std::vector<Image>& levels, std::vector<Image>* differences = nullptr);

}  // namespace nebula
