#include "reconstruct/reconstruct.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "reconstruct/column_model.h"
#include "reconstruct/column_nnls.h"
#include "reconstruct/projection.h"

namespace nebula {

const char* to_string(ReconstructMethod m) {
  switch (m) {
    case ReconstructMethod::Powell: return "powell";
    case ReconstructMethod::Nnls: return "nnls";
    case ReconstructMethod::Absorb: return "absorb";
  }
  return "?";
}

ReconstructMethod parse_reconstruct_method(const std::string& text, const std::string& option) {
  for (ReconstructMethod m : {ReconstructMethod::Powell, ReconstructMethod::Nnls, ReconstructMethod::Absorb})
    if (text == to_string(m)) return m;
  throw Error(option + ": '" + text + "' is not a method (known: powell, nnls, absorb)");
}

namespace {

struct Frame {
  double ox, oy, ax, ay, nx, ny;  // origin, unit axis, unit normal (the "above" side) in pixel coordinates
  double x(double s, double b) const { return ox + s * ax + b * nx; }
  double y(double s, double b) const { return oy + s * ay + b * ny; }
};

bool inside(const Image& im, double x, double y) { return x >= 0 && x <= im.width && y >= 0 && y <= im.height; }

// Bilinear between pixel centres, the edge pixels held beyond them.
float sample(const Image& im, int band, double x, double y) {
  const double fx = std::clamp(x - 0.5, 0.0, double(im.width - 1)), fy = std::clamp(y - 0.5, 0.0, double(im.height - 1));
  const int x0 = std::min(int(fx), im.width - 1), y0 = std::min(int(fy), im.height - 1);
  const int x1 = std::min(x0 + 1, im.width - 1), y1 = std::min(y0 + 1, im.height - 1);
  const double tx = fx - x0, ty = fy - y0;
  // Weights of exactly 0 leave a neighbour out entirely (pixel-aligned axes resample exactly).
  double v = 0;
  auto add = [&](int px, int py, double w) {
    if (w != 0.0) v += w * im.at(band, px, py);
  };
  add(x0, y0, (1 - tx) * (1 - ty));
  add(x1, y0, tx * (1 - ty));
  add(x0, y1, (1 - tx) * ty);
  add(x1, y1, tx * ty);
  return static_cast<float>(v);
}

}  // namespace

StraightImage straighten_image(const Image& image, const ImageAxis& axis, int length, int radius) {
  if (image.width < 1 || image.height < 1 || image.bands.empty() ||
      image.pixels.size() != image.plane_size() * image.bands.size())
    throw ParameterError("image", "has no pixels");
  for (size_t b = 0; b < image.bands.size(); ++b)
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (!std::isfinite(image.at(int(b), x, y)))
          throw ParameterError("image", "band " + image.bands[b] + " pixel (" + std::to_string(x) + ", " +
                                            std::to_string(y) + ") is " + to_text(image.at(int(b), x, y)) +
                                            "; every pixel must be finite");
  if (!std::isfinite(axis.x) || !std::isfinite(axis.y) || !std::isfinite(axis.angle_deg))
    throw ParameterError("axis", "must be three finite numbers X,Y,ANGLE");
  if (!inside(image, axis.x, axis.y))
    throw ParameterError("axis", "the point (" + to_text(axis.x) + ", " + to_text(axis.y) + ") lies outside the " +
                                     std::to_string(image.width) + " x " + std::to_string(image.height) + " image");
  if (length < 0) throw ParameterError("length", "must be >= 0 (0: to the image's edge)");
  if (radius < 0) throw ParameterError("radius", "must be >= 0 (0: to the image's edge)");
  const double t = axis.angle_deg * 3.14159265358979323846 / 180.0;
  // Image y points down: counter-clockwise as seen is (cos, -sin); "above" is the axis turned by +90 degrees.
  Frame f{axis.x, axis.y, std::cos(t), -std::sin(t), -std::sin(t), -std::cos(t)};
  for (double* v : {&f.ax, &f.ay, &f.nx, &f.ny})
    if (std::fabs(*v) < 1e-12) *v = 0.0;  // exact 0 and 90 degrees: pixel-aligned samples
  // The longest run of texel centres along the axis inside the image.
  int max_length = 0;
  while (max_length < (1 << 20) && inside(image, f.x(max_length + 0.5, 0), f.y(max_length + 0.5, 0))) ++max_length;
  if (max_length == 0)
    throw ParameterError("axis", "at " + to_text(axis.angle_deg) + " degrees from (" + to_text(axis.x) + ", " +
                                     to_text(axis.y) + ") it leaves the image before one pixel");
  if (length > max_length)
    throw ParameterError("length", std::to_string(length) + " texels run past the image's edge (at most " +
                                       std::to_string(max_length) + " from the axis point)");
  const int nx = length > 0 ? length : max_length;
  auto row_inside = [&](int j) {
    for (int ix = 0; ix < nx; ++ix)
      for (double side : {1.0, -1.0})
        if (!inside(image, f.x(ix + 0.5, side * (j + 0.5)), f.y(ix + 0.5, side * (j + 0.5)))) return false;
    return true;
  };
  int max_radius = 0;
  while (max_radius < (1 << 20) && row_inside(max_radius)) ++max_radius;
  if (max_radius == 0)
    throw ParameterError("axis", "lies on the image's edge: no pixel on both sides of it");
  if (radius > max_radius)
    throw ParameterError("radius", std::to_string(radius) + " texels run past the image's edge (at most " +
                                       std::to_string(max_radius) + " on both sides of the axis)");
  StraightImage s;
  s.nx = nx;
  s.nr = radius > 0 ? radius : max_radius;
  s.bands = image.bands;
  s.profile.assign(image.bands.size() * size_t(s.nx) * s.nr, 0.0f);
  double sq = 0;
  for (size_t b = 0; b < image.bands.size(); ++b)
    for (int ix = 0; ix < s.nx; ++ix)
      for (int j = 0; j < s.nr; ++j) {
        const double u = ix + 0.5, v = j + 0.5;
        const float above = sample(image, int(b), f.x(u, v), f.y(u, v));
        const float below = sample(image, int(b), f.x(u, -v), f.y(u, -v));
        s.profile[(b * s.nx + ix) * s.nr + j] = 0.5f * (above + below);
        sq += 0.25 * double(above - below) * (above - below);
      }
  s.side_rms = std::sqrt(sq / double(s.profile.size()));
  return s;
}

namespace {

void check_settings(const StraightImage& image, const ReconstructSettings& s) {
  const int nx = image.nx, n = image.nr, nb = int(image.bands.size());
  if (nx < 1 || n < 1 || nb < 1 || image.profile.size() != size_t(nb) * nx * n)
    throw ParameterError("image", "the straightened image is empty");
  if (nb > kMaxBands) throw ParameterError("image", "has " + std::to_string(nb) + " bands; at most " +
                                                        std::to_string(kMaxBands));
  if (!(s.step_texels >= 1e-3f && s.step_texels <= float(std::max(nx, n))))
    throw ParameterError("step_texels", "is " + to_text(s.step_texels) + "; must be in [0.001, the map's size]");
  if (s.method == ReconstructMethod::Powell) {
    const PowellSettings& p = s.powell;
    if (p.coarsest < 1 || (p.coarsest & (p.coarsest - 1)) != 0 || p.coarsest > (1 << 16))
      throw ParameterError("powell.coarsest", "is " + std::to_string(p.coarsest) + "; must be a power of two, 1 to 65536");
    if (p.sweeps < 1) throw ParameterError("powell.sweeps", "must be >= 1");
    if (!(p.tolerance >= 0.0f)) throw ParameterError("powell.tolerance", "must be >= 0");
  }
  if (s.method != ReconstructMethod::Powell && s.backend == Backend::Cuda)
    throw ParameterError("backend", std::string("the ") + to_string(s.method) + " method runs on the CPU only (powell runs on both)");
}

}  // namespace

double choose_smoothness(const ColumnProjection& projection, const StraightImage& image) {
  const double sigma = image.side_rms;
  if (!(sigma > 0.0)) return 0.0;
  // Every k-th column of every band: at most 64 columns per trial.
  const int nb = int(image.bands.size()), n = image.nr;
  std::vector<int> columns;
  const int step = std::max(1, nb * image.nx / 64);
  for (int c = 0; c < nb * image.nx; c += step) columns.push_back(c);
  std::vector<float> x(static_cast<size_t>(n), 0.0f);
  auto residual_rms = [&](double mu) {
    const ColumnNnls nnls(projection, mu);
    double sq = 0;
    for (int c : columns) {
      const float* p = image.profile.data() + size_t(c) * n;
      nnls.solve(p, x.data());
      for (int j = 0; j < n; ++j) {
        double v = -p[j];
        for (int i = projection.col_begin[size_t(j)]; i < n; ++i) v += double(projection.at(j, i)) * x[size_t(i)];
        sq += v * v;
      }
    }
    return std::sqrt(sq / (double(columns.size()) * n));
  };
  // The residual grows with the weight: bisect log10(weight) in [-10, 2].
  double lo = -10.0, hi = 2.0;
  if (residual_rms(std::pow(10.0, lo)) >= sigma) return 0.0;
  if (residual_rms(std::pow(10.0, hi)) <= sigma) return std::pow(10.0, hi);
  for (int k = 0; k < 14; ++k) {
    const double mid = 0.5 * (lo + hi);
    (residual_rms(std::pow(10.0, mid)) < sigma ? lo : hi) = mid;
  }
  return std::pow(10.0, lo);
}

double model_image_error(const ColumnProjection& projection, const StraightImage& image, const AxialMap& map,
                         const std::vector<float>& ratio, float step_texels) {
  const int nb = int(image.bands.size()), n = image.nr;
  std::vector<double> diff(size_t(image.nx), 0.0), norm(size_t(image.nx), 0.0);
  tbb::parallel_for(0, image.nx, [&](int ix) {
    std::vector<float> model(size_t(nb) * n);
    if (ratio.empty()) {
      for (int b = 0; b < nb; ++b) {
        const std::vector<float> col = emitting_column_image(projection, map, ix, b);
        std::copy(col.begin(), col.end(), model.begin() + size_t(b) * n);
      }
    } else {
      std::vector<const float*> e;
      for (int b = 0; b < nb; ++b) e.push_back(map.emission[size_t(b)].data() + map.index(ix, 0));
      // The map's column ix is strided by nx: gather it first.
      std::vector<std::vector<float>> planes(static_cast<size_t>(nb), std::vector<float>(static_cast<size_t>(n)));
      std::vector<float> tau(static_cast<size_t>(n));
      for (int i = 0; i < n; ++i) {
        tau[size_t(i)] = map.tau_v[map.index(ix, i)];
        for (int b = 0; b < nb; ++b) planes[size_t(b)][size_t(i)] = map.emission[size_t(b)][map.index(ix, i)];
      }
      for (int b = 0; b < nb; ++b) e[size_t(b)] = planes[size_t(b)].data();
      model = rendered_column(e, tau.data(), n, ratio, step_texels);
    }
    for (int b = 0; b < nb; ++b) {
      const float* p = image.column(b, ix);
      for (int j = 0; j < n; ++j) {
        const double d = double(model[size_t(b) * n + j]) - p[j];
        diff[size_t(ix)] += d * d;
        norm[size_t(ix)] += double(p[j]) * p[j];
      }
    }
  });
  double d = 0, s = 0;
  for (int ix = 0; ix < image.nx; ++ix) {
    d += diff[size_t(ix)];
    s += norm[size_t(ix)];
  }
  return s > 0 ? std::sqrt(d / s) : std::sqrt(d);
}

AxialMap reconstruct_axial_map(const StraightImage& image, const ReconstructSettings& s, ReconstructReport* report) {
  check_settings(image, s);
  const ColumnProjection projection = build_projection(image.nr, s.step_texels, s.backend);
  return reconstruct_axial_map(image, s, projection, report);
}

AxialMap reconstruct_axial_map(const StraightImage& image, const ReconstructSettings& s,
                               const ColumnProjection& projection, ReconstructReport* report) {
  check_settings(image, s);
  if (s.method == ReconstructMethod::Absorb)
    throw ParameterError("method", "absorb is fitted by reconstruct_absorbing_map (reconstruct/absorb_fit.h)");
  const int nx = image.nx, n = image.nr, nb = int(image.bands.size());
  if (projection.n != n) throw ParameterError("projection", "is for columns of " + std::to_string(projection.n) +
                                                                " texels, the image has " + std::to_string(n));
  ReconstructReport r;
  r.nx = nx;
  r.nr = n;
  r.bands = nb;
  r.side_rms = image.side_rms;
  r.seconds_projection = projection.seconds;
  r.side_difference = projection.side_difference;

  AxialMap map;
  map.nx = nx;
  map.nr = n;
  map.texel = 1.0f;
  map.origin = {0, 0, 0};
  map.axis = {1, 0, 0};
  map.tau_v.assign(map.count(), 0.0f);
  map.emission.assign(size_t(nb), std::vector<float>(map.count(), 0.0f));
  std::vector<float> solution(image.profile.size(), 0.0f);  // [band][ix][i]
  const int columns = nb * nx;
  const auto start = std::chrono::steady_clock::now();
  std::atomic<long long> iterations{0};
  std::atomic<int> not_converged{0};
  if (s.method == ReconstructMethod::Powell && s.backend == Backend::Cuda) {
    long long sweeps = 0;
    solution = powell_columns_cuda(projection, image.profile, columns, s.powell, &sweeps);
    iterations = sweeps;
  } else if (s.method == ReconstructMethod::Powell) {
    const ColumnSystem system = projection.view();
    tbb::parallel_for(tbb::blocked_range<int>(0, columns), [&](const tbb::blocked_range<int>& range) {
      std::vector<float> scratch(6 * size_t(n));
      long long local = 0;
      for (int c = range.begin(); c != range.end(); ++c) {
        float* w = scratch.data();
        const PowellWork work{w, w + n, w + 2 * n, w + 3 * n, w + 4 * n, w + 5 * n};
        SerialTeam team;
        local += powell_column(team, system, image.profile.data() + size_t(c) * n, s.powell, work);
        std::copy(work.e, work.e + n, solution.begin() + size_t(c) * n);
      }
      iterations += local;
    });
  } else {
    const double smoothness = s.smoothness < 0 ? choose_smoothness(projection, image) : s.smoothness;
    r.smoothness = smoothness;
    const ColumnNnls nnls(projection, smoothness);
    tbb::parallel_for(tbb::blocked_range<int>(0, columns), [&](const tbb::blocked_range<int>& range) {
      long long local = 0;
      for (int c = range.begin(); c != range.end(); ++c) {
        const NnlsResult res = nnls.solve(image.profile.data() + size_t(c) * n, solution.data() + size_t(c) * n);
        local += res.iterations;
        if (!res.converged) ++not_converged;
      }
      iterations += local;
    });
  }
  for (int b = 0; b < nb; ++b)
    for (int ix = 0; ix < nx; ++ix)
      for (int i = 0; i < n; ++i) map.emission[size_t(b)][map.index(ix, i)] = solution[(size_t(b) * nx + ix) * n + i];
  r.seconds_solve = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.iterations = iterations;
  r.not_converged = not_converged;
  r.image_error = model_image_error(projection, image, map, {}, s.step_texels);
  map.update_skip_structures();
  if (report) *report = r;
  return map;
}

AxialMap reconstruct_axial_map(const Image& image, const ReconstructSettings& s, ReconstructReport* report) {
  return reconstruct_axial_map(straighten_image(image, s.axis, s.length, s.radius), s, report);
}

}  // namespace nebula
