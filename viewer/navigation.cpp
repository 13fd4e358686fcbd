#include "viewer/navigation.h"

#include <cmath>

namespace nebula::viewer {
namespace {

struct D3 {
  double x, y, z;
};
D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
Vec3 f3(D3 v) { return Vec3{float(v.x), float(v.y), float(v.z)}; }
D3 add(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 mul(double s, D3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double norm(D3 a) { return std::sqrt(dot(a, a)); }
D3 unit(D3 a) { return mul(1.0 / norm(a), a); }

// Rodrigues: v turned by `angle` about the unit axis k.
D3 rotate(D3 v, D3 k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return add(add(mul(c, v), mul(s, cross(k, v))), mul(dot(k, v) * (1 - c), k));
}

// Turns `arm` (eye to look-at, or look-at to eye) by yaw about up and pitch about
// the right vector, keeping 1 degree away from up.
D3 turn(D3 arm, D3 up, double yaw, double pitch) {
  const D3 u = unit(up);
  D3 a = rotate(arm, u, yaw);
  const D3 right = cross(a, u);
  if (norm(right) > 0) {
    const double limit = std::acos(std::fmin(1.0, std::fmax(-1.0, dot(unit(a), u))));  // angle from up
    const double keep = 1.0 * 3.14159265358979 / 180;
    // Pitch up lowers the angle from up; stay within [keep, pi - keep].
    double p = pitch;
    if (limit - p < keep) p = limit - keep;
    if (limit - p > 3.14159265358979 - keep) p = limit - (3.14159265358979 - keep);
    a = rotate(a, unit(right), p);
  }
  return a;
}

}  // namespace

CameraSettings fly_turn(const CameraSettings& c, double yaw, double pitch) {
  CameraSettings out = c;
  const D3 eye = d3(c.position);
  out.look_at = f3(add(eye, turn(sub(d3(c.look_at), eye), d3(c.up), yaw, pitch)));
  return out;
}

CameraSettings fly_move(const CameraSettings& c, double forward, double right, double up) {
  CameraSettings out = c;
  const D3 f = unit(sub(d3(c.look_at), d3(c.position)));
  const D3 r = unit(cross(f, d3(c.up)));
  const D3 u = cross(r, f);
  const D3 step = add(add(mul(forward, f), mul(right, r)), mul(up, u));
  out.position = f3(add(d3(c.position), step));
  out.look_at = f3(add(d3(c.look_at), step));
  return out;
}

CameraSettings orbit(const CameraSettings& c, double yaw, double pitch) {
  CameraSettings out = c;
  const D3 centre = d3(c.look_at);
  out.position = f3(add(centre, turn(sub(d3(c.position), centre), d3(c.up), yaw, pitch)));
  return out;
}

CameraSettings dolly(const CameraSettings& c, double factor) {
  CameraSettings out = c;
  const D3 centre = d3(c.look_at);
  out.position = f3(add(centre, mul(factor, sub(d3(c.position), centre))));
  return out;
}

}  // namespace nebula::viewer
