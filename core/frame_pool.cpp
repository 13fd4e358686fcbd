#include "core/frame_pool.h"

#include <mutex>

namespace nebula {
namespace {

constexpr size_t kKept = 3;  // frames in flight at most: rendering, writing, spare
std::mutex pool_mutex;
std::vector<std::vector<float>>& pool() {
  static std::vector<std::vector<float>> spares;
  return spares;
}

}  // namespace

Image take_frame_image(int width, int height, std::vector<std::string> bands) {
  Image image;
  image.width = width;
  image.height = height;
  image.bands = std::move(bands);
  const size_t n = image.plane_size() * image.bands.size();
  {
    std::lock_guard<std::mutex> lock(pool_mutex);
    auto& spares = pool();
    // Prefer a spare of exactly this size (no fill at all), else any large enough.
    for (int pass = 0; pass < 2 && image.pixels.empty(); ++pass)
      for (auto it = spares.begin(); it != spares.end(); ++it)
        if (pass == 0 ? it->size() == n : it->capacity() >= n) {
          image.pixels = std::move(*it);
          spares.erase(it);
          break;
        }
  }
  image.pixels.resize(n);
  return image;
}

void recycle_frame_image(Image&& image) {
  if (image.pixels.capacity() == 0) return;
  std::vector<float> memory = std::move(image.pixels);
  image = Image();
  std::lock_guard<std::mutex> lock(pool_mutex);
  auto& spares = pool();
  if (spares.size() >= kKept) spares.erase(spares.begin());  // the oldest goes
  spares.push_back(std::move(memory));
}

}  // namespace nebula
