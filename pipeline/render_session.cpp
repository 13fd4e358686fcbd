#include "pipeline/render_session.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "pipeline/run_setup.h"
#include "pipeline/spectral_scene.h"
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
  std::unique_ptr<Scene> next = load_detached(overrides);
  const std::vector<SceneInput> inputs = scene_->inputs;
  // The preparation points into the old scene: keep the old one alive until
  // the next render has taken what it can from that preparation.
  if (prepared_ || spectral_) retired_ = std::move(scene_);
  scene_ = std::move(next);
  if (scene_->inputs.empty() || scene_->inputs.front().key != "scene") {
    // load_scene_text does not know the file: carry the file's own entry over.
    for (const SceneInput& i : inputs)
      if (i.key == "scene") scene_->inputs.insert(scene_->inputs.begin(), i);
  }
  return *scene_;
}

std::unique_ptr<Scene> RenderSession::load_detached(const std::vector<std::string>& overrides) const {
  std::vector<std::string> all = overrides_;
  all.insert(all.end(), overrides.begin(), overrides.end());
  return std::make_unique<Scene>(load_scene_text(text_, name_, base_dir_, all, scene_.get()));
}

std::vector<RenderSession::PlannedPoint> RenderSession::plan(const std::vector<std::vector<std::string>>& points) {
  groups_.clear();
  ready_.clear();
  std::vector<PlannedPoint> out(points.size());
  std::map<std::string, int> group_of, field_of;
  // Every point's scene first (the check before any work), kept without its
  // grids where it brings a new field; then those fields' tables.
  struct Candidate {
    std::unique_ptr<Scene> scene;
    SharedDiffuseMember member;
  };
  std::vector<std::vector<Candidate>> candidates;
  for (size_t i = 0; i < points.size(); ++i) {
    std::unique_ptr<Scene> scene = load_detached(points[i]);
    if (scene->spectral) continue;  // the spectral renderer bakes its fields at its own nodes
    SceneBands bands = scene_bands(*scene);
    DiffuseKeys keys = diffuse_keys(*scene, bands, options_);
    if (keys.photons.empty()) continue;
    auto g = group_of.emplace(keys.photons, int(groups_.size()));
    if (g.second) {
      groups_.emplace_back();
      candidates.emplace_back();
    }
    auto f = field_of.emplace(keys.field, int(field_of.size()));
    if (f.second) {
      scene->density = {};
      scene->emission.clear();
      candidates[size_t(g.first->second)].push_back({std::move(scene), {std::move(keys), std::move(bands), {}}});
    }
    out[i] = {g.first->second, f.first->second};
  }
  for (size_t g = 0; g < groups_.size(); ++g) {
    if (candidates[g].size() < 2) continue;
    for (Candidate& c : candidates[g]) {
      c.member.tables = resolve_tables(*c.scene, {options_.backend, options_.table_photons, options_.progress});
      groups_[g].members.push_back(std::move(c.member));
    }
  }
  // A group of one field shares nothing.
  for (PlannedPoint& p : out)
    if (p.group >= 0 && candidates[size_t(p.group)].size() < 2) p = {};
  return out;
}

bool RenderSession::hand_shared_field(const Scene& scene, PreparedGrid& previous) {
  if (groups_.empty() && ready_.empty()) return false;
  const std::string key = diffuse_keys(scene, scene_bands(scene), options_).field;
  if (key.empty() || key == previous.diffuse_key) return false;  // prepare_grid reuses the previous field
  auto it = ready_.find(key);
  if (it == ready_.end()) {
    for (PlanGroup& g : groups_) {
      const auto at = std::find_if(g.members.begin(), g.members.end(),
                                   [&](const SharedDiffuseMember& m) { return m.keys.field == key; });
      if (at == g.members.end()) continue;
      // This field and the group's next ones not yet baked, as many as one pass takes.
      std::vector<size_t> chosen{size_t(at - g.members.begin())};
      for (size_t j = 0; j < g.members.size() && chosen.size() < size_t(kMaxAlbedoSlots); ++j)
        if (j != chosen.front()) chosen.push_back(j);
      if (chosen.size() < 2) break;
      std::vector<SharedDiffuseMember> members;
      for (size_t j : chosen) members.push_back(g.members[j]);
      ready_.clear();
      for (SharedDiffuse& f : bake_shared_diffuse(scene, members, options_)) {
        const std::string k = f.key;
        ready_.emplace(k, std::move(f));
      }
      std::sort(chosen.begin(), chosen.end());
      for (auto j = chosen.rbegin(); j != chosen.rend(); ++j) g.members.erase(g.members.begin() + long(*j));
      break;
    }
    it = ready_.find(key);
    if (it == ready_.end()) return false;
  }
  previous.diffuse = std::move(it->second.field);
  previous.diffuse_key = key;
  previous.report.diffuse = it->second.report;
  ready_.erase(it);
  return true;
}

RenderOutput RenderSession::render(const std::vector<std::string>& overrides) {
  const auto start = std::chrono::steady_clock::now();
  const Scene& scene = load(overrides);
  RenderOutput out;
  if (scene.spectral) {  // the spectral renderer, keeping what the overrides left unchanged
    prepared_.reset();
    spectral_ = prepare_spectral(scene, options_, spectral_.get());
    retired_.reset();
    out = render_prepared_spectral(*spectral_, scene.camera);
  } else if (scene.axial) {  // its own renderer, whole each time (render_scene)
    prepared_.reset();
    spectral_.reset();
    retired_.reset();
    out = render_scene(scene, options_);
  } else {
    spectral_.reset();
    PreparedGrid previous = prepared_ ? std::move(*prepared_) : PreparedGrid{};
    const bool handed = hand_shared_field(scene, previous);
    auto next = std::make_unique<PreparedGrid>(prepare_grid(scene, options_, std::move(previous)));
    if (handed) next->report.diffuse.reused = false;  // baked for it, ahead: not reused
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
