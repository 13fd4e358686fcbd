#pragma once
// The one camera model: perspective, orthographic (the telescope view of a
// distant observer) and the 180-degree fulldome fisheye (azimuthal equidistant
// dome master). CameraSettings is what a scene file or a program sets;
// make_camera turns it into the Camera every renderer traces rays with.
// Pixel (0, 0) is the top-left corner of the image.
#include <optional>
#include <string>

#include "core/hd.h"
#include "core/math.h"
#include "core/vec3.h"

namespace nebula {

enum class Projection : int { Perspective = 0, Orthographic = 1, Fisheye = 2 };

// A pixel's width at distance t along its ray, in world units: width_at_eye +
// t x spread, and the directions of its sides (the camera's right and up; zero
// where the pixels have no fixed sides, the fisheye's). The marchers' starlight
// near a star takes the pixel's mean of 1/b from these
// (illumination/chord_irradiance.h).
struct RayFootprint {
  float width_at_eye = 0;
  float spread = 0;
  Vec3 side_x, side_y;
  NEBULA_HD float width(float t) const { return width_at_eye + fmaxf(t, 0.0f) * spread; }
};

struct Camera {
  Projection projection = Projection::Perspective;
  Vec3 position;
  Vec3 forward, right, up;  // orthonormal; right x up = -forward is not assumed
  int width = 0, height = 0;
  float tan_half_fov = 0;   // perspective: vertical half-angle
  float half_width = 0;     // orthographic: half extent in world units
  float half_height = 0;
  // The frame the image covers, in pixels of the full-resolution image; a
  // coarser pyramid level (multires/) renders the same frame with pixels
  // pixel_span times larger (image width ceil(frame_width / pixel_span)).
  // 0: the image's own width and height.
  int frame_width = 0, frame_height = 0;
  float pixel_span = 1;

  // The ray through the centre of pixel (px, py); false where the pixel shows
  // nothing (outside the dome circle of the fisheye).
  NEBULA_HD bool ray(int px, int py, Vec3& origin, Vec3& dir) const {
    return ray_through(px + 0.5f, py + 0.5f, origin, dir);
  }

  // The ray through the image point (fx, fy) in pixels from the top-left
  // corner (pixel (px, py) spans [px, px + 1) x [py, py + 1)).
  NEBULA_HD bool ray_through(float fx, float fy, Vec3& origin, Vec3& dir) const {
    const float fw = float(frame_width > 0 ? frame_width : width);
    const float fh = float(frame_height > 0 ? frame_height : height);
    const float u = 2.0f * fx * pixel_span / fw - 1.0f;   // -1 left .. 1 right
    const float v = 1.0f - 2.0f * fy * pixel_span / fh;  // 1 top .. -1 bottom
    if (projection == Projection::Perspective) {
      const float aspect = fw / fh;
      origin = position;
      dir = normalize(forward + (u * aspect * tan_half_fov) * right + (v * tan_half_fov) * up);
      return true;
    }
    if (projection == Projection::Orthographic) {
      origin = position + (u * half_width) * right + (v * half_height) * up;
      dir = forward;
      return true;
    }
    // Azimuthal equidistant: the distance from the centre is proportional to
    // the angle from the zenith (forward), 90 degrees at the rim.
    const float rho = sqrtf(u * u + v * v);
    if (rho > 1.0f) return false;
    const float theta = rho * 0.5f * kPi;
    const float cos_phi = rho > 0.0f ? u / rho : 1.0f, sin_phi = rho > 0.0f ? v / rho : 0.0f;
    origin = position;
    dir = normalize(cosf(theta) * forward + (sinf(theta) * cos_phi) * right +
                    (sinf(theta) * sin_phi) * up);
    return true;
  }

  // A pixel's footprint (at the image's centre; the projections keep it
  // nearly constant across the frame at the fields of view used).
  NEBULA_HD RayFootprint footprint() const {
    const float fh = float(frame_height > 0 ? frame_height : height);
    const float per_pixel = 2.0f * pixel_span / fmaxf(fh, 1.0f);  // image units per pixel
    if (projection == Projection::Perspective) return {0.0f, per_pixel * tan_half_fov, right, up};
    if (projection == Projection::Orthographic) return {per_pixel * half_height, 0.0f, right, up};
    // Fisheye: 90 degrees from the centre to the rim; its pixels turn with the
    // azimuth, so no fixed sides.
    return {0.0f, per_pixel * 0.5f * kPi, {}, {}};
  }

  // The unit direction from `point` towards the eye along the ray that sees
  // it: the camera's position (perspective, fisheye), or against the view
  // direction (orthographic).
  NEBULA_HD Vec3 to_eye(Vec3 point) const {
    if (projection == Projection::Orthographic) return -forward;
    const Vec3 d = position - point;
    const float r = length(d);
    return r > 0.0f ? (1.0f / r) * d : -forward;
  }
};

struct CameraSettings {
  Projection projection = Projection::Perspective;
  Vec3 position{0, 0, -10}, look_at{0, 0, 0}, up{0, 1, 0};
  double fov_deg = 40;      // perspective: full vertical field of view, (0, 180)
  double ortho_width = 0;   // orthographic: world units across the image width, > 0
  int width = 512, height = 512;  // pixels, 1 to kMaxCameraPixels; a fisheye needs width == height
  double exposure = 1.0;    // multiplies the rendered radiance, > 0
};

constexpr int kMaxCameraPixels = 1 << 16;  // per side
// Radiance is single precision: with stars up to 1e12 L_sun a larger exposure
// could overflow a pixel to infinity (and NaN after tone mapping).
constexpr double kMaxCameraExposure = 1e12;
// Camera points farther than this from the origin (parsecs, about 70 times the
// observable universe) lose the view direction in single precision.
constexpr double kMaxCameraDistancePc = 1e12;

// The first setting that makes no camera: its field name as CameraSettings
// spells it (and a scene file's [camera] table does; "kind" for the
// projection) and the reason, or nothing.
struct CameraIssue {
  std::string field, reason;
};
std::optional<CameraIssue> camera_issue(const CameraSettings& s);

// Builds the camera; throws ParameterError("camera.<field>", reason) for the
// first camera_issue.
Camera make_camera(const CameraSettings& s);

// The same frame at half the resolution (ceil of each size): pixel i covers
// pixels 2i and 2i + 1 of `c` (the pyramid's image levels).
Camera coarser_camera(const Camera& c);

// Where a point appears in the image, the inverse of Camera::ray_through:
// (x, y) in pixels from the top-left corner, and the pixel's measure there:
// its solid angle in sr (perspective, fisheye) or its area in world units
// squared (orthographic). Nothing when the point is behind the camera (or its
// image plane), or outside the fisheye's dome.
struct ImagePoint {
  double x = 0, y = 0;
  double pixel_measure = 0;
};
std::optional<ImagePoint> project_point(const Camera& c, Vec3 p);

// "perspective", "orthographic", "fisheye" (the scene file's camera.kind).
const char* to_string(Projection p);
// The projection a name gives; false for any other name.
bool parse_projection(const std::string& name, Projection& out);

}  // namespace nebula
