#pragma once
#include <cmath>

#include "core/hd.h"

namespace nebula {

// Minimal float vector usable on host and device.
struct Vec3 {
  float x = 0, y = 0, z = 0;
};

NEBULA_HD Vec3 make_vec3(float x, float y, float z) { return Vec3{x, y, z}; }
NEBULA_HD Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
NEBULA_HD Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
NEBULA_HD Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
NEBULA_HD Vec3 operator*(float s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
NEBULA_HD Vec3 operator*(Vec3 a, float s) { return s * a; }
NEBULA_HD float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
NEBULA_HD Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
NEBULA_HD float length(Vec3 a) { return sqrtf(dot(a, a)); }
NEBULA_HD Vec3 normalize(Vec3 a) { return (1.0f / length(a)) * a; }

// Orthonormal frame (t, b) completing the unit vector n, without any
// division that can vanish: |copysign(1, n.z) + n.z| >= 1 (Duff et al. 2017,
// "Building an Orthonormal Basis, Revisited", JCGT 6(1)).
NEBULA_HD void orthonormal_frame(Vec3 n, Vec3& t, Vec3& b) {
  const float sign = copysignf(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

}  // namespace nebula
