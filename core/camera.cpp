#include "raycast/camera.h"

#include <cmath>

#include "core/error.h"

namespace nebula {

const char* to_string(Projection p) {
  switch (p) {
    case Projection::Perspective: return "perspective";
    case Projection::Orthographic: return "orthographic";
    default: return "fisheye";
  }
}

Camera make_camera(const CameraSettings& s) {
  if (s.width < 1 || s.height < 1) throw Error("camera: width and height must be positive");
  const Vec3 view = s.look_at - s.position;
  if (!(length(view) > 0)) throw Error("camera.look_at: must differ from camera.position");
  Camera c;
  c.projection = s.projection;
  c.position = s.position;
  c.width = c.frame_width = s.width;
  c.height = c.frame_height = s.height;
  c.forward = normalize(view);
  const Vec3 side = cross(c.forward, s.up);
  if (!(length(side) > 1e-6f * length(s.up)))
    throw Error("camera.up: must not be parallel to the view direction");
  c.right = normalize(side);
  c.up = cross(c.right, c.forward);
  if (s.projection == Projection::Perspective) {
    if (!(s.fov_deg > 0 && s.fov_deg < 180)) throw Error("camera.fov_deg: must be in (0, 180)");
    c.tan_half_fov = static_cast<float>(std::tan(s.fov_deg * kPiD / 360.0));
  } else if (s.projection == Projection::Orthographic) {
    if (!(s.ortho_width > 0)) throw Error("camera.ortho_width: must be positive for an orthographic camera");
    c.half_width = static_cast<float>(0.5 * s.ortho_width);
    c.half_height = c.half_width * s.height / s.width;
  } else if (s.width != s.height) {
    throw Error("camera: a fisheye dome master must be square (width == height)");
  }
  return c;
}

Camera coarser_camera(const Camera& c) {
  Camera out = c;
  if (out.frame_width <= 0) out.frame_width = c.width;
  if (out.frame_height <= 0) out.frame_height = c.height;
  out.width = (c.width + 1) / 2;
  out.height = (c.height + 1) / 2;
  out.pixel_span = 2 * c.pixel_span;
  return out;
}

}  // namespace nebula
