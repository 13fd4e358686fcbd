#include "pipeline/render_session.h"

#include <chrono>
#include <fstream>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "pipeline/run_setup.h"
#include "scene/scene_file.h"

namespace nebula {

RenderSession RenderSession::from_file(const std::string& path, std::vector<std::string> overrides,
                                       RenderOptions options) {
  // load_scene reads and checks the file (its errors name it); the session
  // keeps the text so that every later load applies overrides to the same bytes.
  Scene first = load_scene(path, overrides);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  RenderSession s;
  s.text_ = text.str();
  s.name_ = path;
  const size_t slash = path.find_last_of('/');
  s.base_dir_ = slash == std::string::npos ? "" : path.substr(0, slash);
  s.overrides_ = std::move(overrides);
  s.options_ = options;
  s.scene_ = std::make_unique<Scene>(std::move(first));
  return s;
}

RenderSession RenderSession::from_text(std::string text, std::string name, std::string base_dir,
                                       std::vector<std::string> overrides, RenderOptions options) {
  RenderSession s;
  s.text_ = std::move(text);
  s.name_ = std::move(name);
  s.base_dir_ = std::move(base_dir);
  s.overrides_ = std::move(overrides);
  s.options_ = options;
  s.scene_ = std::make_unique<Scene>(load_scene_text(s.text_, s.name_, s.base_dir_, s.overrides_));
  return s;
}

const Scene& RenderSession::load(const std::vector<std::string>& overrides) {
  std::vector<std::string> all = overrides_;
  all.insert(all.end(), overrides.begin(), overrides.end());
  auto next = std::make_unique<Scene>(load_scene_text(text_, name_, base_dir_, all, scene_.get()));
  const std::vector<SceneInput> inputs = scene_->inputs;
  // The preparation points into the old scene: keep the old one alive until
  // the next render has taken what it can from that preparation.
  if (prepared_) retired_ = std::move(scene_);
  scene_ = std::move(next);
  if (scene_->inputs.empty() || scene_->inputs.front().key != "scene") {
    // load_scene_text does not know the file: carry the file's own entry over.
    for (const SceneInput& i : inputs)
      if (i.key == "scene") scene_->inputs.insert(scene_->inputs.begin(), i);
  }
  return *scene_;
}

RenderOutput RenderSession::render(const std::vector<std::string>& overrides) {
  const auto start = std::chrono::steady_clock::now();
  const Scene& scene = load(overrides);
  RenderOutput out;
  if (scene.axial) {
    prepared_.reset();
    retired_.reset();
    out = render_scene(scene, options_);
  } else {
    PreparedGrid previous = prepared_ ? std::move(*prepared_) : PreparedGrid{};
    auto next = std::make_unique<PreparedGrid>(prepare_grid(scene, options_, std::move(previous)));
    prepared_ = std::move(next);
    retired_.reset();
    out = render_prepared(*prepared_, scene.camera);
  }
  out.report.total_seconds = pipeline_detail::seconds_since(start);
  return out;
}

TruthRenderOutput RenderSession::truth(const std::vector<std::string>& overrides, const TruthOptions& options) {
  const Scene& scene = load(overrides);
  return truth_scene(scene, options);
}

}  // namespace nebula
