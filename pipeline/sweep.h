#pragma once
// Parameter sweeps (`nebula sweep`, the Python module): one scene rendered
// over a grid of values of scene keys, through a RenderSession so that work
// that does not depend on the swept keys is done once (the grids; the star
// bakes unless a star moves; docs/sweep.md says what each key costs).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "imageio/image_output.h"
#include "pipeline/render_session.h"

namespace nebula {

// The most grid points a sweep takes unless forced.
constexpr uint64_t kMaxSweepPoints = 100000;

struct SweepOptions {
  bool truth = false;    // the ground truth instead of the fast renderer
  TruthOptions truth_options;
  bool force = false;    // allow more than kMaxSweepPoints points
  // Fast sweeps: points whose diffuse fields differ only in the albedos
  // share one photon pass per band (RenderSession::plan), computed group by
  // group; false: every point bakes its own, bit for bit a separate render.
  bool share_photons = true;
};

struct SweepResult {
  std::vector<CubeAxis> axes;
  std::vector<Image> images;      // one per point, the first axis slowest
  std::vector<RunReport> reports;  // one per point
  ImageMetadata metadata;         // what every point's metadata shares, the axes' WCS added
  double seconds = 0;
};

// The grid points' overrides, first axis slowest ("KEY=VALUE" per axis).
std::vector<std::vector<std::string>> sweep_points(const std::vector<CubeAxis>& axes);

// Every point's scene is loaded (and so checked: an unknown key, a bad
// value) before any rendering; errors name the key and the point's value.
// Points are computed in an order that keeps the points sharing photons
// together; the result is in grid order.
// Refuses an empty axis, a repeated key and more than kMaxSweepPoints points
// unless forced. `on_point` (may be empty) hears each point done (index, count).
SweepResult run_sweep(RenderSession& session, const std::vector<CubeAxis>& axes, const SweepOptions& options,
                      const std::function<void(size_t, size_t)>& on_point = {});

}  // namespace nebula
