#include <gtest/gtest.h>

#include "core/gpu.h"
#include "raycast/axial_test_scenes.h"

namespace nebula {
namespace {

TEST(AxialRendererGpu, Placeholder) {
  std::string why;
  if (!gpu_available(&why)) GTEST_SKIP() << why;
}

}  // namespace
}  // namespace nebula
