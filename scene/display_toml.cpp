#include "scene/display_toml.h"

#include <cmath>
#include <string>

#include "core/error.h"

namespace nebula::scene_detail {

DisplaySettings parse_display(const toml::node& node, const FailFunction& fail) {
  auto refuse = [&](const std::string& key, const std::string& reason) {
    fail(key, reason);
    throw Error(key + ": " + reason);
  };
  const toml::table* t = node.as_table();
  if (t == nullptr) refuse("display", "must be a table");
  for (auto&& [k, v] : *t) {
    (void)v;
    const std::string name(k.str());
    if (name != "stretch" && name != "auto_exposure" && name != "percentile" && name != "white" && name != "softening")
      refuse("display." + name, "unknown key (known here: stretch, auto_exposure, percentile, white, softening)");
  }
  auto number = [&](const char* name) {
    const toml::node* v = t->get(name);
    const std::string key = std::string("display.") + name;
    if (v->is_integer()) return double(v->as_integer()->get());
    if (v->is_floating_point() && std::isfinite(v->as_floating_point()->get())) return v->as_floating_point()->get();
    refuse(key, "must be a finite number");
    return 0.0;
  };
  DisplaySettings d;
  if (const toml::node* v = t->get("stretch")) {
    if (!v->is_string() || !parse_stretch(v->as_string()->get(), d.stretch))
      refuse("display.stretch", "must be \"linear\", \"asinh\" or \"log\"");
  }
  if (const toml::node* v = t->get("auto_exposure")) {
    if (!v->is_boolean()) refuse("display.auto_exposure", "must be true or false");
    d.auto_exposure = v->as_boolean()->get();
  }
  if (t->get("percentile")) {
    d.percentile = number("percentile");
    if (!(d.percentile > 0 && d.percentile <= 100))
      refuse("display.percentile", "is " + to_text(d.percentile) + "; must be in (0, 100]");
  }
  if (t->get("white")) {
    d.white = number("white");
    if (!(d.white > 0 && d.white <= 1e12)) refuse("display.white", "is " + to_text(d.white) + "; must be in (0, 1e12]");
  }
  if (t->get("softening")) {
    d.softening = number("softening");
    if (!(d.softening >= 1e-6 && d.softening <= 1e6))
      refuse("display.softening", "is " + to_text(d.softening) + "; must be in [1e-6, 1e6]");
  }
  return d;
}

}  // namespace nebula::scene_detail
