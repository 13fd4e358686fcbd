#pragma once
// Pixel memory for frames in a sequence (an animation, the viewer). A fresh
// full-HD image is 25 MB that the system hands out page by page and zero-fills
// (about 9 ms, more than a GPU renders the frame in); a frame already written
// can lend its memory to the next one instead.
#include <string>
#include <vector>

#include "core/image.h"

namespace nebula {

// An image of this size whose pixel values are unspecified: for a caller that
// overwrites every pixel (a GPU frame's download). Its memory is that of a
// recycled frame when one is waiting, a fresh allocation otherwise.
Image take_frame_image(int width, int height, std::vector<std::string> bands);

// Hands a finished frame's memory to the next take_frame_image (a few are
// kept; the rest are freed).
void recycle_frame_image(Image&& image);

}  // namespace nebula
