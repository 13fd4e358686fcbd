#include "spectral/spectral_renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "core/error.h"
#include "illumination/star_pixels_cpu.h"

namespace nebula::spectral {
namespace {
void check(const SpectralRenderInputs& in) {
  if (!in.density || !in.model) throw Error("spectral render: no density grid or model");
  if (int(in.lights.size()) != in.model->n_stars)
    throw Error("spectral render: the model was built for " + std::to_string(in.model->n_stars) + " stars, got " +
                std::to_string(in.lights.size()));
  for (const SpectralLight& l : in.lights)
    if (!l.depth_v || l.depth_v->size() != in.density->shape.count())
      throw Error("spectral render: a star has no baked depth for this grid");
  if (in.emission.size() != in.model->emission.size())
    throw Error("spectral render: the model has " + std::to_string(in.model->emission.size()) +
                " emission components, got " + std::to_string(in.emission.size()) + " weights");
  for (const SpectralEmissionWeight& e : in.emission)
    if (e.grid && e.grid->size() != in.density->shape.count())
      throw Error("spectral render: an emission weight grid does not have the density's shape");
  if (const SpectralDiffuseLight* d = in.diffuse) {
    const SpectralModel& m = *in.model;
    const size_t n = size_t(m.settings.table_nodes), voxels = in.density->shape.count();
    if ((!in.table && in.node_tables.empty()) || n < 1)
      throw Error("spectral render: light between voxels needs the voxels' table (table_nodes >= 1)");
    const bool device = d->on_device();
    bool sizes = d->node_power.size() == in.lights.size() &&
                 (device ? d->device_light.size() == in.lights.size() && d->device_peak.size() == n
                         : d->light.size() == in.lights.size() && d->peak.size() == n);
    for (size_t k = 0; sizes && k < in.lights.size(); ++k) {
      sizes = (device ? d->device_light[k].size() : d->light[k].size()) == n && d->node_power[k].size() == n;
      for (size_t j = 0; sizes && j < n; ++j)
        sizes = device ? d->device_light[k][j].holds(voxels * sizeof(float)) : d->light[k][j].size() == voxels;
    }
    for (size_t j = 0; sizes && j < n; ++j)
      sizes = device ? d->device_peak[j].holds(voxels * sizeof(float)) : d->peak[j].size() == voxels;
    if (!sizes)
      throw Error("spectral render: the light between voxels is not one array per star and table node (" +
                  std::to_string(n) + ") of the density's shape");
  }
  if (in.model->varying()) {
    const SpectralModel& m = *in.model;
    if (!in.node_tables.empty() && in.node_tables.size() != m.node_kappa.size())
      throw Error("spectral render: " + std::to_string(in.node_tables.size()) + " node tables for " +
                  std::to_string(m.node_kappa.size()) + " table nodes");
    for (size_t k = 0; k < in.node_tables.size(); ++k) {
      const ScatteringTable* t = in.node_tables[k];
      if (!t || std::fabs(t->albedo - m.node_albedo[k]) > 1e-6 || std::fabs(t->g - m.node_g[k]) > 1e-6)
        throw Error("spectral render: table node " + std::to_string(k) + " needs a table for albedo " +
                    to_text(m.node_albedo[k]) + ", g " + to_text(m.node_g[k]));
      if (t->tau != in.node_tables[0]->tau || t->mu_edges != in.node_tables[0]->mu_edges)
        throw Error("spectral render: the node tables have different axes");
    }
    if (in.diffuse && in.node_tables.empty())
      throw Error("spectral render: light between voxels needs the node tables (their response)");
    if (m.settings.method == SpectralMethod::Double && !in.node_tables.empty())
      throw Error("spectral render: the double integral would need a table per wavelength for varying albedo and g; "
                  "it takes them in the thin-voxel limit only (no node tables)");
  } else if (in.table && in.model->settings.table_nodes > 0 &&
      (std::fabs(in.table->albedo - in.albedo) > 1e-6 || std::fabs(in.table->g - in.g) > 1e-6))
    throw Error("spectral render: the table is for albedo " + to_text(in.table->albedo) + ", g " +
                to_text(in.table->g) + "; the dust has albedo " + to_text(in.albedo) + ", g " + to_text(in.g));
}
}  // namespace

void set_table(SpectralSceneView& view, const SpectralRenderInputs& in, const float* P, const float* C,
               const std::vector<const float*>& node_P, const std::vector<const float*>& node_C) {
  if (in.model->varying()) {  // every node its own albedo and g: nodes even in the thin limit
    view.n_nodes = in.model->settings.table_nodes;
    if (in.node_tables.empty()) return;  // the thin limit at each node
    view.table = nebula::view_of(*in.node_tables[0]);  // the axes
    view.table.P = node_P[0];
    view.table.C = node_C[0];
    for (size_t k = 0; k < node_P.size(); ++k) {
      view.node_P[k] = node_P[k];
      view.node_C[k] = node_C[k];
    }
  } else {
    if (!in.table || in.model->settings.table_nodes == 0) return;  // the thin limit
    view.table = nebula::view_of(*in.table);
    view.table.P = P;
    view.table.C = C;  // the mean over a chord's angles near a star (pair_weights)
    view.n_nodes = in.model->settings.table_nodes;
  }
  // The rays that can have chords seeing a star over several angle bins (tables/chord_phase.h).
  if (view.table.bins.kind == AngularBinning::UniformTheta && view.table.C)
    view.near_star_radius = NearStarRadius::phase(in.density->shape.voxel, view.table.n_mu);
}

NodeTable node_table(const SpectralRenderInputs& in, const SpectralSceneView& view) {
  static_assert(kMaxTableNodes == 4, "a node cell holds four values");
  NodeTable out;
  const int n = view.n_nodes;
  const bool varying = in.model->varying();
  if (n < 1 || (varying ? in.node_tables.size() != size_t(n) : !in.table)) return out;
  std::vector<TableView> tables;
  float c[kMaxTableNodes], c_min = 1e30f, c_max = 0.0f;  // node m's scattering depth per unit tau_V
  for (int m = 0; m < n; ++m) {
    tables.push_back(nebula::view_of(varying ? *in.node_tables[size_t(m)] : *in.table));
    c[m] = (varying ? view.node_albedo[m] : in.albedo) * view.node_kappa[m];
    c_min = std::min(c_min, c[m]);
    c_max = std::max(c_max, c[m]);
  }
  const TableView& t = tables[0];
  if (!(c_min > 0.0f) || t.n_tau < 2 || t.n_mu < 1) return out;
  // Rows half the table's spacing apart at the deepest node: the nodes' values are the
  // table's piecewise-linear lookups, whose kinks at its rows (its Monte-Carlo noise among
  // them) a linear interpolant over a row of length d smooths by up to |slope jump| d / 4.
  constexpr double kRowsPerTableRow = 2;
  const double spacing = double(t.tau_max) / (t.n_tau - 1), step = spacing / c_max / kRowsPerTableRow;
  const double rows = std::ceil(double(t.tau_max) / (double(c_min) * step)) + 1;  // until every node clamps
  if (rows > 65536) return out;
  out.rows = int(rows);
  out.step = float(step);
  out.values.assign(size_t(out.rows) * t.n_mu * 4, 0.0f);
  tbb::parallel_for(0, out.rows, [&](int i) {
    for (int k = 0; k < t.n_mu; ++k)
      for (int m = 0; m < n; ++m)
        out.values[(size_t(i) * t.n_mu + k) * 4 + m] = tables[size_t(m)].lookup_at(c[m] * float(i * step), float(k));
  });
  return out;
}

void use_node_table(SpectralSceneView& view, const NodeTable& nodes, const float* values) {
  view.node_table = values;
  view.node_table_rows = nodes.rows;
  view.node_table_inv_step = 1.0f / nodes.step;
}

void set_emission(SpectralSceneView& view, const SpectralRenderInputs& in, const std::vector<const float*>& grids) {
  for (size_t c = 0; c < in.emission.size(); ++c) {
    view.emission[c].weight = grids[c];
    view.emission[c].scale = in.emission[c].scale;
  }
}

DiffuseTerms diffuse_terms(const SpectralRenderInputs& in, const SpectralSceneView& view) {
  if (!in.diffuse) return {};
  const int n = view.n_nodes, S = int(in.lights.size());
  const size_t voxels = in.density->shape.count();
  SpectralDiffuseLight downloaded;  // a CUDA pass' arrays, for the CPU
  if (in.diffuse->on_device()) {
    const auto fetch = [&](const DeviceMirror& m) {
      std::vector<float> host(voxels);
      m.download(host.data(), voxels * sizeof(float));
      return host;
    };
    for (const auto& star : in.diffuse->device_light) {
      downloaded.light.emplace_back();
      for (const DeviceMirror& m : star) downloaded.light.back().push_back(fetch(m));
    }
    for (const DeviceMirror& m : in.diffuse->device_peak) downloaded.peak.push_back(fetch(m));
    downloaded.node_power = in.diffuse->node_power;
  }
  const SpectralDiffuseLight& d = in.diffuse->on_device() ? downloaded : *in.diffuse;
  DiffuseTerms out;
  out.terms.resize(voxels * S * size_t(n + 1));
  out.eye_tau.resize(voxels);
  tbb::parallel_for(size_t(0), voxels, size_t(8192), [&](size_t v0) {
    for (size_t v = v0; v < std::min(voxels, v0 + 8192); ++v) {
      float H[kMaxTableNodes], power[kMaxTableNodes], peak[kMaxTableNodes];
      for (int k = 0; k < S; ++k) {
        for (int m = 0; m < n; ++m) {
          H[m] = d.light[size_t(k)][size_t(m)][v];
          power[m] = float(d.node_power[size_t(k)][size_t(m)]);
        }
        diffuse_voxel_terms(view, H, power, &out.terms[(v * S + k) * size_t(n + 1)]);
      }
      for (int m = 0; m < n; ++m) peak[m] = d.peak[size_t(m)][v];
      out.eye_tau[v] = diffuse_eye_depth(view, peak, in.density->tau_v[v]);
    }
  });
  return out;
}

Image render_spectral(const SpectralRenderInputs& in, Backend backend, double* seconds) {
  check(in);
  return backend == Backend::Cuda ? render_spectral_cuda(in, seconds) : render_spectral_cpu(in, seconds);
}

Image render_spectral_cpu(const SpectralRenderInputs& in, double* seconds) {
  check(in);
  const SpectralModel& m = *in.model;
  std::vector<SpectralStarView> stars;
  for (size_t k = 0; k < in.lights.size(); ++k)
    stars.push_back({in.lights[k].position, float(in.lights[k].luminosity_lsun), in.lights[k].depth_v->data(),
                     m.temperature_u.empty() ? 0.0f : m.temperature_u[k]});
  SpectralSceneView view = view_of(m);
  view.density = in.density->view();
  view.stars = stars.data();
  view.n_stars = int(stars.size());
  view.albedo = in.albedo;
  view.g = in.g;
  view.footprint = in.camera.footprint();
  std::vector<const float*> node_P, node_C;
  std::vector<std::vector<float>> cumulative;  // each table's rows' integrals (the chord's mean near a star)
  for (const ScatteringTable* t : in.node_tables) {
    cumulative.push_back(cumulative_rows(*t));
    node_P.push_back(t->P.data());
    node_C.push_back(cumulative.back().data());
  }
  const std::vector<float> C = in.table ? cumulative_rows(*in.table) : std::vector<float>{};
  set_table(view, in, in.table ? in.table->P.data() : nullptr, C.empty() ? nullptr : C.data(), node_P, node_C);
  const NodeTable nodes = node_table(in, view);
  if (!nodes.values.empty()) use_node_table(view, nodes, nodes.values.data());
  const auto start = std::chrono::steady_clock::now();  // the per-view work is timed with the march
  const DiffuseTerms diffuse = diffuse_terms(in, view);
  if (in.diffuse) {
    view.diffuse = diffuse.terms.data();
    view.eye_tau = diffuse.eye_tau.data();
  }
  std::vector<const float*> grids;
  for (const SpectralEmissionWeight& e : in.emission) grids.push_back(e.grid ? e.grid->data() : nullptr);
  set_emission(view, in, grids);
  std::vector<std::string> names;
  for (int k = 0; k < m.planes(); ++k) names.push_back("acc" + std::to_string(k));
  Image image(in.camera.width, in.camera.height, names);
  const GridShape& g = in.density->shape;
  VoxelLightWorkspace local;
  VoxelLightWorkspace& work = in.workspace ? *in.workspace : local;
  if (m.settings.method == SpectralMethod::VoxelLight) {
    work.light.resize(g.count() * 4 * size_t(m.n_acc) * m.basis.size());
    work.near.resize(g.count());
    view.near_distance = float(m.settings.near_voxels) * g.voxel;
  }
  if (m.settings.method == SpectralMethod::VoxelLight) {  // the per-view pre-pass (timed with the march)
    constexpr int kRow = 16;  // voxels side by side in the vectorised geometry
    tbb::parallel_for(tbb::blocked_range<int>(0, g.nz * g.ny), [&](const auto& rows) {
      for (int r = rows.begin(); r != rows.end(); ++r)
        for (int x = 0; x < g.nx; x += kRow)
          voxel_light<kRow>(view, in.camera, x, r % g.ny, r / g.ny, work.light.data(), work.near.data());
    });
    view.voxel_light = work.light.data();
    view.near_stars = work.near.data();
  }
  dispatch_method(m.settings.method, [&](auto method) {
    tbb::parallel_for(tbb::blocked_range<int>(0, in.camera.height), [&](const auto& rows) {
      DynamicAccumulators acc;  // run-time extents: registers matter on the GPU, not here
      float em[kMaxEmissionPlanes];
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < in.camera.width; ++x) {
          Vec3 origin, dir;
          if (!in.camera.ray(x, y, origin, dir)) continue;
          if (passes_near_a_star(view, origin, dir))
            march_spectral<method(), true>(view, origin, dir, acc, em);
          else
            march_spectral<method(), false>(view, origin, dir, acc, em);
          store_accumulators(view, acc, &image.at(0, x, y), image.plane_size());
          store_emission(view, em, &image.at(0, x, y), image.plane_size());
        }
    });
    // The pixels at each star's image, with many rays each (illumination/star_pixels.h).
    std::vector<Vec3> positions;
    if (in.star_pixels)
      for (const SpectralLight& l : in.lights) positions.push_back(l.position);
    std::atomic<uint64_t> no_clamps{0};  // the spectral marcher counts none
    march_star_pixels_cpu(in.camera, positions, m.planes(), 1.0f, image.pixels.data(),
                          [&](Vec3 origin, Vec3 dir, float narrowing, float* out, size_t stride) {
                            SpectralSceneView sub = view;
                            sub.footprint = sub_pixel_footprint(view.footprint, narrowing);
                            DynamicAccumulators acc;
                            float em[kMaxEmissionPlanes];
                            march_spectral<method(), true>(sub, origin, dir, acc, em);
                            store_accumulators(sub, acc, out, stride);
                            store_emission(sub, em, out, stride);
                            return uint64_t(0);
                          },
                          no_clamps);
  });
  if (seconds) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return image;
}

Image resolve_filters(const Image& acc, const SpectralModel& m, float exposure) {
  Image out(acc.width, acc.height, m.filter_names);
  const size_t plane = acc.plane_size();
  const int F = int(m.filter_names.size()), W = m.planes();
  if (acc.bands.size() != size_t(W))
    throw Error("spectral resolve: the image has " + std::to_string(acc.bands.size()) + " planes; the model " +
                std::to_string(W));
  tbb::parallel_for(size_t(0), plane, size_t(4096), [&](size_t p0) {
    for (size_t p = p0; p < std::min(plane, p0 + 4096); ++p)
      for (int f = 0; f < F; ++f) {
        double v = 0.0;
        for (int k = 0; k < W; ++k) v += double(m.resolve[size_t(f) * W + k]) * acc.pixels[k * plane + p];
        out.pixels[f * plane + p] = exposure * float(v);
      }
  });
  return out;
}

}  // namespace nebula::spectral
