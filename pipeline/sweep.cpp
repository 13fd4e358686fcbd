#include "pipeline/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <set>
#include <tuple>

#include "core/error.h"
#include "pipeline/run_setup.h"

namespace nebula {

std::vector<std::vector<std::string>> sweep_points(const std::vector<CubeAxis>& axes) {
  std::vector<std::vector<std::string>> points{{}};
  for (const CubeAxis& axis : axes) {
    std::vector<std::vector<std::string>> next;
    for (const std::vector<std::string>& p : points)
      for (double v : axis.values) {
        std::vector<std::string> q = p;
        q.push_back(axis.key + "=" + to_text(v));
        next.push_back(std::move(q));
      }
    points = std::move(next);
  }
  return points;
}

namespace {

void check_axes(const std::vector<CubeAxis>& axes, bool force) {
  if (axes.empty()) throw ParameterError("grid", "no axis to sweep");
  std::set<std::string> keys;
  double points = 1;
  for (const CubeAxis& a : axes) {
    if (a.key.empty()) throw ParameterError("grid", "an axis without a key");
    if (!keys.insert(a.key).second) throw ParameterError("grid", a.key + " is swept twice");
    if (a.values.empty()) throw ParameterError("grid", a.key + ": no values (an empty range)");
    for (double v : a.values)
      if (!std::isfinite(v)) throw ParameterError("grid", a.key + ": a value that is not a finite number");
    points *= double(a.values.size());
  }
  if (points > double(kMaxSweepPoints) && !force)
    throw ParameterError("grid", to_text(points) + " points, more than " + std::to_string(kMaxSweepPoints) +
                                     " (force it to run anyway)");
}

// The entries every point's metadata holds with the same value.
MetaEntries common_entries(const std::vector<ImageMetadata>& all) {
  MetaEntries out;
  for (const auto& [key, value] : all.front().entries) {
    bool same = true;
    for (const ImageMetadata& m : all) {
      bool found = false;
      for (const auto& [k, v] : m.entries)
        if (k == key) {
          found = v == value;
          break;
        }
      if (!found) {
        same = false;
        break;
      }
    }
    if (same) out.emplace_back(key, value);
  }
  return out;
}

// The axes' WCS (FITS axes 4...: the last axis first), as the image's own
// axes are described (pipeline/run_setup.cpp camera_wcs): evenly spaced
// values get a linear axis; others an index axis, their values in the
// cube's per-axis extension.
void add_axes_wcs(MetaEntries& entries, const std::vector<CubeAxis>& axes) {
  for (auto& [key, value] : entries)
    if (key == "WCSAXES") value = MetaValue(int(3 + axes.size()));
  for (size_t k = 0; k < axes.size(); ++k) {
    const CubeAxis& a = axes[k];
    const std::string n = std::to_string(3 + axes.size() - k);
    const double step = a.values.size() > 1 ? a.values[1] - a.values[0] : 1.0;
    bool linear = true;
    for (size_t i = 0; i < a.values.size(); ++i)
      linear = linear && std::fabs(a.values[i] - (a.values[0] + double(i) * step)) <= 1e-9 * (1 + std::fabs(step) * i);
    std::string type = a.key;
    if (type.size() > 8) type = type.substr(type.size() - 8);  // CTYPE is a short name; the key is in SWEEP<n>
    entries.push_back({"CTYPE" + n, linear ? type : "INDEX"});
    entries.push_back({"CRPIX" + n, 1.0});
    entries.push_back({"CRVAL" + n, linear ? a.values[0] : 0.0});
    entries.push_back({"CDELT" + n, linear ? step : 1.0});
    entries.push_back({"SWEEP" + n, a.key});
  }
}

}  // namespace

SweepResult run_sweep(RenderSession& session, const std::vector<CubeAxis>& axes, const SweepOptions& o,
                      const std::function<void(size_t, size_t)>& on_point) {
  const auto start = std::chrono::steady_clock::now();
  check_axes(axes, o.force);
  const std::vector<std::vector<std::string>> points = sweep_points(axes);
  // Every point's scene first: bad keys and values fail before any work
  // (planning loads every point).
  const bool plan_sharing = !o.truth && o.share_photons;
  if (!plan_sharing)
    for (const std::vector<std::string>& p : points) session.load(p);
  // The order of the work: points sharing photons together, equal fields
  // next to each other (the session reuses the previous point's field).
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), size_t(0));
  // The plan ends with the sweep, however it ends: later renders of the
  // session bake their own fields.
  struct PlanEnds {
    RenderSession& session;
    ~PlanEnds() { session.plan({}); }
  } plan_ends{session};
  if (plan_sharing) {
    const std::vector<RenderSession::PlannedPoint> plan = session.plan(points);
    std::vector<size_t> group_first(points.size(), points.size()), field_first(points.size(), points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      if (plan[i].group >= 0) group_first[size_t(plan[i].group)] = std::min(group_first[size_t(plan[i].group)], i);
      if (plan[i].field >= 0) field_first[size_t(plan[i].field)] = std::min(field_first[size_t(plan[i].field)], i);
    }
    auto rank = [&](size_t i) {
      return std::make_tuple(plan[i].group >= 0 ? group_first[size_t(plan[i].group)] : i,
                             plan[i].field >= 0 ? field_first[size_t(plan[i].field)] : i, i);
    };
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rank(a) < rank(b); });
  }
  SweepResult r;
  r.axes = axes;
  r.images.resize(points.size());
  r.reports.resize(points.size());
  std::vector<ImageMetadata> metadata(points.size());
  for (size_t done = 0; done < order.size(); ++done) {
    const size_t i = order[done];
    if (o.truth) {
      TruthRenderOutput t = session.truth(points[i], o.truth_options);
      r.images[i] = std::move(t.image);
      metadata[i] = std::move(t.metadata);
      r.reports[i] = std::move(t.report);
    } else {
      RenderOutput f = session.render(points[i]);
      r.images[i] = std::move(f.image);
      metadata[i] = std::move(f.metadata);
      r.reports[i] = std::move(f.report);
    }
    if (on_point) on_point(done + 1, points.size());
  }
  r.metadata = metadata.front();
  r.metadata.entries = common_entries(metadata);
  add_axes_wcs(r.metadata.entries, axes);
  r.metadata.entries.push_back({"sweep", std::string(o.truth ? "the ground truth" : "the fast renderer")});
  r.seconds = pipeline_detail::seconds_since(start);
  return r;
}

}  // namespace nebula
