#include "scene/camera_path.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace nebula {
namespace {

struct D3 {
  double x = 0, y = 0, z = 0;
};
D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
Vec3 f3(D3 v) { return Vec3{float(v.x), float(v.y), float(v.z)}; }
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator*(double s, D3 a) { return {s * a.x, s * a.y, s * a.z}; }
double norm(D3 a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }

// a (t1 - t) / (t1 - t0) + b (t - t0) / (t1 - t0)
D3 blend(D3 a, D3 b, double t0, double t1, double t) {
  return ((t1 - t) / (t1 - t0)) * a + ((t - t0) / (t1 - t0)) * b;
}

// Constant speed: arc length from this many points per segment (Simpson's
// rule would need smoothness at the ends; a fine polyline is within 1e-5 of
// the length for the gentle curves of camera paths, and monotone for inversion).
constexpr int kSamples = 256;

bool same_time(double t, double key) { return std::fabs(t - key) <= 1e-9 * std::fmax(1.0, std::fabs(key)); }

}  // namespace

const char* to_string(PathTiming timing) {
  return timing == PathTiming::ConstantSpeed ? "constant_speed" : "keyframes";
}

bool parse_path_timing(const std::string& name, PathTiming& out) {
  for (PathTiming t : {PathTiming::Keyframes, PathTiming::ConstantSpeed})
    if (name == to_string(t)) {
      out = t;
      return true;
    }
  return false;
}

Vec3 centripetal_catmull_rom(Vec3 p0v, Vec3 p1v, Vec3 p2v, Vec3 p3v, double u) {
  D3 p0 = d3(p0v), p1 = d3(p1v), p2 = d3(p2v), p3 = d3(p3v);
  const double d12 = norm(p2 - p1);
  if (!(d12 > 0)) return p1v;
  // A neighbour on top of its end point would make a knot interval of zero.
  if (!(norm(p1 - p0) > 1e-9 * d12)) p0 = p1 + (p1 - p2);
  if (!(norm(p3 - p2) > 1e-9 * d12)) p3 = p2 + (p2 - p1);
  const double t0 = 0, t1 = t0 + std::sqrt(norm(p1 - p0)), t2 = t1 + std::sqrt(d12),
               t3 = t2 + std::sqrt(norm(p3 - p2));
  const double t = t1 + u * (t2 - t1);
  const D3 a1 = blend(p0, p1, t0, t1, t), a2 = blend(p1, p2, t1, t2, t), a3 = blend(p2, p3, t2, t3, t);
  const D3 b1 = blend(a1, a2, t0, t2, t), b2 = blend(a2, a3, t1, t3, t);
  return f3(blend(b1, b2, t1, t2, t));
}

std::optional<CameraPathIssue> camera_path_issue(const CameraPath& path, const CameraSettings& base) {
  const std::string keys = "animation.keyframes";
  if (path.keys.size() < 2)
    return CameraPathIssue{keys, "has " + std::to_string(path.keys.size()) +
                                     " keyframe" + (path.keys.size() == 1 ? "" : "s") +
                                     "; a camera path needs at least 2"};
  for (size_t i = 0; i < path.keys.size(); ++i) {
    const CameraKeyframe& k = path.keys[i];
    const std::string key = keys + "." + std::to_string(i);
    if (!std::isfinite(k.time) || std::fabs(k.time) > 1e9)
      return CameraPathIssue{key + ".time", "is " + to_text(k.time) + "; must be a finite time in seconds"};
    if (i > 0 && !(k.time > path.keys[i - 1].time))
      return CameraPathIssue{key + ".time", "is " + to_text(k.time) + "; keyframe times must increase (the one before is " +
                                                to_text(path.keys[i - 1].time) + ")"};
    CameraSettings c = base;
    c.position = k.position;
    c.look_at = k.look_at;
    c.up = k.up;
    c.fov_deg = k.fov_deg;
    if (auto issue = camera_issue(c)) return CameraPathIssue{key + "." + issue->field, issue->reason};
  }
  return std::nullopt;
}

CameraPathSampler::CameraPathSampler(CameraPath path, const CameraSettings& base)
    : path_(std::move(path)), base_(base) {
  if (auto issue = camera_path_issue(path_, base_)) throw Error(issue->key + ": " + issue->reason);
  const size_t n = path_.keys.size();
  // Fritsch-Carlson tangents of the field of view, per unit u of each segment.
  std::vector<double> delta(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) delta[i] = path_.keys[i + 1].fov_deg - path_.keys[i].fov_deg;
  fov_slopes_.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const double left = i > 0 ? delta[i - 1] : delta[0], right = i + 1 < n ? delta[i] : delta[n - 2];
    if (left * right <= 0) continue;  // an extremum (or flat): no overshoot past the key
    const double m = 0.5 * (left + right);
    const double limit = 3.0 * std::fmin(std::fabs(left), std::fabs(right));
    fov_slopes_[i] = std::copysign(std::fmin(std::fabs(m), limit), m);
  }
  if (path_.timing == PathTiming::ConstantSpeed) {
    arc_.reserve((n - 1) * kSamples + 1);
    arc_.push_back(0);
    Vec3 previous = path_.keys[0].position;
    for (size_t s = 0; s + 1 < n; ++s)
      for (int j = 1; j <= kSamples; ++j) {
        const Vec3 p = settings_at(Place{int(s), double(j) / kSamples, -1}).position;
        arc_.push_back(arc_.back() + norm(d3(p) - d3(previous)));
        previous = p;
      }
  }
}

CameraPathSampler::Place CameraPathSampler::place(double time) const {
  const std::vector<CameraKeyframe>& k = path_.keys;
  const int last = int(k.size()) - 1;
  time = std::clamp(time, k.front().time, k.back().time);
  if (path_.timing == PathTiming::Keyframes) {
    for (int i = 0; i <= last; ++i)
      if (same_time(time, k[i].time)) return Place{std::min(i, last - 1), i == last ? 1.0 : 0.0, i};
    int s = int(std::upper_bound(k.begin(), k.end(), time, [](double t, const CameraKeyframe& key) { return t < key.time; }) -
                k.begin()) - 1;
    s = std::clamp(s, 0, last - 1);
    return Place{s, (time - k[s].time) / (k[s + 1].time - k[s].time), -1};
  }
  // Constant speed: the fraction of the duration is the fraction of the length.
  if (same_time(time, k.front().time)) return Place{0, 0.0, 0};
  if (same_time(time, k.back().time)) return Place{last - 1, 1.0, last};
  const double target = (time - k.front().time) / (k.back().time - k.front().time) * arc_.back();
  const size_t j = size_t(std::upper_bound(arc_.begin(), arc_.end(), target) - arc_.begin());
  const size_t i = std::clamp<size_t>(j, 1, arc_.size() - 1) - 1;  // arc_[i] <= target < arc_[i + 1]
  const double span = arc_[i + 1] - arc_[i];
  const double fraction = span > 0 ? (target - arc_[i]) / span : 0.0;
  const double sample = double(i) + std::clamp(fraction, 0.0, 1.0);
  const int segment = std::min(int(sample / kSamples), last - 1);
  return Place{segment, std::clamp(sample / kSamples - segment, 0.0, 1.0), -1};
}

CameraSettings CameraPathSampler::settings_at(const Place& p) const {
  CameraSettings c = base_;
  const std::vector<CameraKeyframe>& k = path_.keys;
  if (p.key >= 0) {
    c.position = k[size_t(p.key)].position;
    c.look_at = k[size_t(p.key)].look_at;
    c.up = k[size_t(p.key)].up;
    c.fov_deg = k[size_t(p.key)].fov_deg;
    return c;
  }
  const int n = int(k.size()), s = p.segment;
  const CameraKeyframe &k1 = k[size_t(s)], &k2 = k[size_t(s + 1)];
  // Beyond the ends, the neighbour is the reflection of the next key.
  auto spline = [&](Vec3 CameraKeyframe::*field) {
    const Vec3 a = k1.*field, b = k2.*field;
    const Vec3 before = s > 0 ? k[size_t(s - 1)].*field : a + (a - b);
    const Vec3 after = s + 2 < n ? k[size_t(s + 2)].*field : b + (b - a);
    return centripetal_catmull_rom(before, a, b, after, p.u);
  };
  c.position = spline(&CameraKeyframe::position);
  c.look_at = spline(&CameraKeyframe::look_at);
  const D3 up = d3(spline(&CameraKeyframe::up));
  const double up_length = norm(up);
  c.up = up_length > 0 ? f3((1.0 / up_length) * up) : k1.up;
  // Cubic Hermite of the field of view in u.
  const double u = p.u, u2 = u * u, u3 = u2 * u;
  c.fov_deg = (2 * u3 - 3 * u2 + 1) * k1.fov_deg + (u3 - 2 * u2 + u) * fov_slopes_[size_t(s)] +
              (-2 * u3 + 3 * u2) * k2.fov_deg + (u3 - u2) * fov_slopes_[size_t(s + 1)];
  return c;
}

CameraSettings CameraPathSampler::at(double time) const { return settings_at(place(time)); }

Vec3 CameraPathSampler::position_at(double time) const { return at(time).position; }

}  // namespace nebula
