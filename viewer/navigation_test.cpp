#include "viewer/navigation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace nebula::viewer {
namespace {

double dist(Vec3 a, Vec3 b) { return length(a - b); }

CameraSettings start() {
  CameraSettings c;
  c.position = {1, -3, 1};
  c.look_at = {1, 1, 1};
  c.up = {0, 0, 1};
  return c;
}

TEST(Navigation, OrbitKeepsTheDistanceAndThePivot) {
  const CameraSettings c = start();
  const CameraSettings o = orbit(c, 0.7, 0.3);
  EXPECT_NEAR(dist(o.position, o.look_at), 4.0, 1e-5);
  EXPECT_EQ(o.look_at.x, c.look_at.x);
  EXPECT_GT(o.position.z, c.position.z);  // pitched up: the eye rises
  // A quarter turn about +z takes the eye from -y of the pivot to +x of it.
  const CameraSettings q = orbit(c, M_PI / 2, 0);
  EXPECT_NEAR(q.position.x, 5.0, 1e-5);
  EXPECT_NEAR(q.position.y, 1.0, 1e-5);
  // Pitching past the pole stops short of it: the view keeps an up vector.
  const CameraSettings top = orbit(c, 0, 3.0);
  EXPECT_FALSE(camera_issue(top).has_value());
}

TEST(Navigation, FlyTurnKeepsTheEyeAndMoveKeepsTheDirection) {
  const CameraSettings c = start();
  const CameraSettings t = fly_turn(c, 0.2, 0.1);
  EXPECT_EQ(t.position.y, c.position.y);
  EXPECT_NEAR(dist(t.position, t.look_at), 4.0, 1e-5);
  EXPECT_GT(t.look_at.z, c.look_at.z);  // pitched up: looks higher
  const CameraSettings m = fly_move(c, 1.0, 0.5, 0.25);
  EXPECT_NEAR(m.position.y, -2.0, 1e-6);  // forward is +y
  EXPECT_NEAR(m.position.x, 1.5, 1e-6);   // right is +x
  EXPECT_NEAR(m.position.z, 1.25, 1e-6);  // up is +z
  EXPECT_NEAR(dist(m.position, m.look_at), 4.0, 1e-6);
  const CameraSettings d = dolly(c, 0.5);
  EXPECT_NEAR(dist(d.position, d.look_at), 2.0, 1e-6);
}

}  // namespace
}  // namespace nebula::viewer
