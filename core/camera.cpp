#include "core/camera.h"

#include <cmath>
#include <utility>

#include "core/error.h"

namespace nebula {

const char* to_string(Projection p) {
  switch (p) {
    case Projection::Perspective: return "perspective";
    case Projection::Orthographic: return "orthographic";
    default: return "fisheye";
  }
}

bool parse_projection(const std::string& name, Projection& out) {
  for (Projection p : {Projection::Perspective, Projection::Orthographic, Projection::Fisheye})
    if (name == to_string(p)) {
      out = p;
      return true;
    }
  return false;
}

namespace {

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string vec_text(Vec3 v) { return "[" + to_text(v.x) + ", " + to_text(v.y) + ", " + to_text(v.z) + "]"; }

}  // namespace

std::optional<CameraIssue> camera_issue(const CameraSettings& c) {
  if (!finite(c.position)) return CameraIssue{"position", "must be finite"};
  if (!finite(c.look_at)) return CameraIssue{"look_at", "must be finite"};
  if (!finite(c.up)) return CameraIssue{"up", "must be finite"};
  // In double: a float dot or cross product of large or nearly parallel vectors loses the answer.
  auto norm = [](Vec3 v) { return std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z); };
  if (norm(c.position) > kMaxCameraDistancePc)
    return CameraIssue{"position", "is " + vec_text(c.position) + ", farther than " + to_text(kMaxCameraDistancePc) +
                                       " pc from the origin (single precision would lose the view direction)"};
  if (norm(c.look_at) > kMaxCameraDistancePc)
    return CameraIssue{"look_at", "is " + vec_text(c.look_at) + ", farther than " + to_text(kMaxCameraDistancePc) +
                                      " pc from the origin (single precision would lose the view direction)"};
  const double dx = double(c.look_at.x) - c.position.x, dy = double(c.look_at.y) - c.position.y,
               dz = double(c.look_at.z) - c.position.z;
  const double view = std::sqrt(dx * dx + dy * dy + dz * dz);
  const double scale = std::fmax(1.0, norm(c.position));
  if (!(view > 1e-6 * scale))
    return CameraIssue{"look_at", "equals the position " + vec_text(c.position) + ": the view direction has zero length"};
  const double ux = c.up.x, uy = c.up.y, uz = c.up.z;
  const double up = std::sqrt(ux * ux + uy * uy + uz * uz);
  if (!(up > 0)) return CameraIssue{"up", "must not be the zero vector"};
  // |d x u| / (|d| |u|) = sin of the angle between them.
  const double cx = dy * uz - dz * uy, cy = dz * ux - dx * uz, cz = dx * uy - dy * ux;
  const double sine = std::sqrt(cx * cx + cy * cy + cz * cz) / (view * up);
  if (!(sine > 1e-6))
    return CameraIssue{"up", "is " + vec_text(c.up) +
                                 ", parallel to the view direction (look_at - position); choose an up vector across it"};
  if (!(std::isfinite(c.fov_deg) && c.fov_deg > 0 && c.fov_deg < 180))
    return CameraIssue{"fov_deg", "is " + to_text(c.fov_deg) + "; must be in (0, 180)"};
  if (c.projection == Projection::Orthographic) {
    if (!(std::isfinite(c.ortho_width) && c.ortho_width > 0))
      return CameraIssue{"ortho_width", "is " + to_text(c.ortho_width) +
                                            "; an orthographic camera needs a width (parsecs across the image) > 0"};
  } else if (!(std::isfinite(c.ortho_width) && c.ortho_width >= 0)) {
    return CameraIssue{"ortho_width", "is " + to_text(c.ortho_width) + "; must be >= 0"};
  }
  for (const auto& [field, size] : {std::pair<const char*, int>{"width", c.width}, {"height", c.height}}) {
    if (size < 1) return CameraIssue{field, "is " + std::to_string(size) + "; must be >= 1"};
    if (size > kMaxCameraPixels)
      return CameraIssue{field, "is " + std::to_string(size) + "; must be <= " + std::to_string(kMaxCameraPixels)};
  }
  if (c.projection == Projection::Fisheye && c.width != c.height)
    return CameraIssue{"height", "is " + std::to_string(c.height) + " but width is " + std::to_string(c.width) +
                                     "; a fisheye dome master must be square"};
  if (!(std::isfinite(c.exposure) && c.exposure > 0))
    return CameraIssue{"exposure", "is " + to_text(c.exposure) + "; must be > 0"};
  if (c.exposure > kMaxCameraExposure)
    return CameraIssue{"exposure", "is " + to_text(c.exposure) + "; must be at most " + to_text(kMaxCameraExposure) +
                                       " (radiance is single precision: a larger exposure overflows pixels)"};
  return std::nullopt;
}

Camera make_camera(const CameraSettings& s) {
  if (auto issue = camera_issue(s)) throw ParameterError("camera." + issue->field, issue->reason);
  Camera c;
  c.projection = s.projection;
  c.position = s.position;
  c.width = c.frame_width = s.width;
  c.height = c.frame_height = s.height;
  c.forward = normalize(s.look_at - s.position);
  const Vec3 side = cross(c.forward, s.up);
  // camera_issue decides in double; a float cross product can still vanish.
  if (!(length(side) > 1e-6f * length(s.up)))
    throw ParameterError("camera.up", "is " + vec_text(s.up) + ", too close to the view direction");
  c.right = normalize(side);
  c.up = cross(c.right, c.forward);
  if (s.projection == Projection::Perspective) {
    c.tan_half_fov = static_cast<float>(std::tan(s.fov_deg * kPiD / 360.0));
  } else if (s.projection == Projection::Orthographic) {
    c.half_width = static_cast<float>(0.5 * s.ortho_width);
    c.half_height = c.half_width * s.height / s.width;
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

std::optional<ImagePoint> project_point(const Camera& c, Vec3 p) {
  const double fw = c.frame_width > 0 ? c.frame_width : c.width;
  const double fh = c.frame_height > 0 ? c.frame_height : c.height;
  const double span = c.pixel_span;
  const Vec3 d = p - c.position;
  const double along = dot(d, c.forward), across = dot(d, c.right), upward = dot(d, c.up);
  // Image coordinates u (-1 left .. 1 right) and v (1 top .. -1 bottom), and
  // the size of a pixel in them.
  double u = 0, v = 0, measure = 0;
  const double du = 2.0 * span / fw, dv = 2.0 * span / fh;
  if (c.projection == Projection::Perspective) {
    if (!(along > 0)) return std::nullopt;
    const double aspect = fw / fh, t = c.tan_half_fov;
    u = across / along / (aspect * t);
    v = upward / along / t;
    // The tangent plane's pixel (du aspect t by dv t) seen at cos(theta) off axis.
    const double cos_theta = along / std::sqrt(double(dot(d, d)));
    measure = du * aspect * t * dv * t * cos_theta * cos_theta * cos_theta;
  } else if (c.projection == Projection::Orthographic) {
    if (!(along > 0)) return std::nullopt;
    u = across / c.half_width;
    v = upward / c.half_height;
    measure = du * c.half_width * dv * c.half_height;
  } else {
    const double sideways = std::hypot(across, upward);
    if (!(sideways > 0 || along > 0)) return std::nullopt;
    // atan2, not acos: exact near the zenith.
    const double theta = std::atan2(sideways, along);
    if (theta > 0.5 * kPiD) return std::nullopt;
    const double rho = theta / (0.5 * kPiD);
    u = sideways > 0 ? rho * across / sideways : 0.0;
    v = sideways > 0 ? rho * upward / sideways : 0.0;
    // Equidistant: d(theta) = (pi/2) d(rho) and d(phi) = d(area) / (rho d(rho)),
    // so a solid angle sin(theta) d(theta) d(phi) is (pi/2)^2 sin(theta)/theta d(area).
    const double sinc = theta > 1e-8 ? std::sin(theta) / theta : 1.0;
    measure = 0.25 * kPiD * kPiD * sinc * du * dv;
  }
  return ImagePoint{(u + 1.0) * 0.5 * fw / span, (1.0 - v) * 0.5 * fh / span, measure};
}

}  // namespace nebula
