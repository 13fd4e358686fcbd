#include "scene/camera_path_toml.h"

#include <cmath>
#include <initializer_list>
#include <string_view>

#include "core/error.h"

namespace nebula::scene_detail {
namespace {

const std::initializer_list<std::string_view> kAnimationKeys = {"timing", "keyframes"};
const std::initializer_list<std::string_view> kKeyframeKeys = {"time", "position", "look_at", "up", "fov_deg"};

struct Reader {
  const FailFunction& fail;

  [[noreturn]] void refuse(const std::string& key, const std::string& reason) const {
    fail(key, reason);
    throw Error(key + ": " + reason);  // fail throws; this keeps the compiler sure of it
  }

  void known(const toml::table& t, const std::string& path, std::initializer_list<std::string_view> keys) const {
    for (auto&& [k, v] : t) {
      (void)v;
      bool ok = false;
      for (std::string_view known : keys) ok = ok || known == k.str();
      if (ok) continue;
      std::string list;
      for (std::string_view known : keys) list += (list.empty() ? "" : ", ") + std::string(known);
      refuse(path + "." + std::string(k.str()), "unknown key (known here: " + list + ")");
    }
  }

  double number(const toml::node& n, const std::string& key) const {
    double v = 0;
    if (n.is_integer())
      v = double(n.as_integer()->get());
    else if (n.is_floating_point())
      v = n.as_floating_point()->get();
    else
      refuse(key, "must be a number");
    if (!std::isfinite(v)) refuse(key, "must be finite, got " + to_text(v));
    return v;
  }

  Vec3 vec3(const toml::node& n, const std::string& key) const {
    const toml::array* a = n.as_array();
    if (a == nullptr || a->size() != 3) refuse(key, "must be an array of 3 numbers [x, y, z]");
    double c[3];
    for (int i = 0; i < 3; ++i) {
      c[i] = number((*a)[size_t(i)], key + "[" + std::to_string(i) + "]");
      if (std::fabs(c[i]) > 1e30) refuse(key, "component " + to_text(c[i]) + " is too large");
    }
    return Vec3{float(c[0]), float(c[1]), float(c[2])};
  }
};

}  // namespace

CameraPath parse_camera_path(const toml::node& node, const CameraSettings& camera, const FailFunction& fail) {
  const Reader r{fail};
  const toml::table* t = node.as_table();
  if (t == nullptr) r.refuse("animation", "must be a table");
  r.known(*t, "animation", kAnimationKeys);
  CameraPath path;
  if (const toml::node* v = t->get("timing")) {
    if (!v->is_string()) r.refuse("animation.timing", "must be a string (keyframes or constant_speed)");
    if (!parse_path_timing(v->as_string()->get(), path.timing))
      r.refuse("animation.timing", "'" + v->as_string()->get() + "' is not a timing (known: keyframes, constant_speed)");
  }
  const toml::node* keys = t->get("keyframes");
  if (keys == nullptr) r.refuse("animation.keyframes", "missing: [[animation.keyframes]] entries (at least 2)");
  const toml::array* a = keys->as_array();
  if (a == nullptr) r.refuse("animation.keyframes", "must be an array of tables ([[animation.keyframes]])");
  for (size_t i = 0; i < a->size(); ++i) {
    const std::string key = "animation.keyframes." + std::to_string(i);
    const toml::table* k = (*a)[i].as_table();
    if (k == nullptr) r.refuse(key, "must be a table (time, position, look_at, up, fov_deg)");
    r.known(*k, key, kKeyframeKeys);
    CameraKeyframe frame;
    frame.look_at = camera.look_at;
    frame.up = camera.up;
    frame.fov_deg = camera.fov_deg;
    for (const char* required : {"time", "position"})
      if (k->get(required) == nullptr) r.refuse(key + "." + required, "missing required key");
    frame.time = r.number(*k->get("time"), key + ".time");
    frame.position = r.vec3(*k->get("position"), key + ".position");
    if (const toml::node* v = k->get("look_at")) frame.look_at = r.vec3(*v, key + ".look_at");
    if (const toml::node* v = k->get("up")) frame.up = r.vec3(*v, key + ".up");
    if (const toml::node* v = k->get("fov_deg")) frame.fov_deg = r.number(*v, key + ".fov_deg");
    path.keys.push_back(frame);
  }
  if (auto issue = camera_path_issue(path, camera)) r.refuse(issue->key, issue->reason);
  return path;
}

}  // namespace nebula::scene_detail
