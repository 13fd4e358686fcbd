#include "app/print_report.h"

#include <cstdio>

namespace nebula::app {
namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

void print_headline(const RunReport& r) {
  const char* verb = r.renderer == "truth" ? "truth" : "rendered";
  std::printf("%s %s: %dx%d %s, %zu band(s), %zu star(s), ", verb, r.scene.c_str(), r.width, r.height,
              r.camera.c_str(), r.bands.size(), r.stars);
  if (r.axial) {
    const AxialMapReport& a = *r.axial;
    std::printf("axial map %dx%d, skip %s%s, step %g texel", a.nx, a.nr, a.skip.c_str(),
                a.skip_used != a.skip ? " (ran naive: the map has no empty texel)" : "", a.step_texels);
  } else {
    std::printf("grid %dx%dx%d, ", r.grid.nx, r.grid.ny, r.grid.nz);
    if (r.truth)
      std::printf("%d spp", r.truth->spp);
    else if (r.spectral)
      std::printf("%s", r.mode.c_str());
    else
      std::printf("%s traversal", r.mode == "exact" ? "exact" : "smooth");
  }
  std::printf(", %s\n", to_string(r.backend));
}

// Light scattered between voxels: the diffuse field's bake, or the pyramid's levels.
void print_multiple_scattering(const RunReport& r) {
  const DiffuseReport& d = r.diffuse;
  if (d.done && d.axial) {
    std::printf("  diffuse field (light scattered between cells): %zu band(s) x %llu photons through the map voxelized "
                "to %dx%dx%d, harmonics to degree %d (response %s) on %d x %d (x, r) cells of %g pc, ring averages; "
                "%.3g s (photon passes %.3g s); noise of one 3D cell before the ring average, relative L2 of its l = 0 "
                "part:",
                d.bands, (unsigned long long)d.photons_per_band, d.photon_grid.nx, d.photon_grid.ny, d.photon_grid.nz,
                d.order, d.lanczos ? "Lanczos-tapered" : "untapered", d.cells.nx, d.cells.ny, d.cells.voxel, d.wall_seconds, d.seconds);
  } else if (d.done) {
    std::printf("  diffuse field (light scattered between voxels): %zu band(s) x %llu photons, harmonics to degree %d ",
                d.bands, (unsigned long long)d.photons_per_band, d.order);
    if (d.zonal > 0) std::printf("and zonal degrees to %d of %d star(s)' light ", d.zonal, d.zonal_stars);
    std::printf("(response %s) ", d.lanczos ? "Lanczos-tapered" : "untapered");
    std::printf("on %dx%dx%d cells of %d voxel(s); %.3g s (photon passes %.3g s); noise, relative L2 of its l = 0 part:",
                d.cells.nx, d.cells.ny, d.cells.nz, d.voxels_per_cell, d.wall_seconds, d.seconds);
    if (d.reused) std::printf(" [reused: nothing it depends on changed; figures of its bake]");
    if (d.shared_with > 0)
      std::printf(" [one photon pass per band for this and %d other albedo set(s) of the sweep; figures of that pass]",
                  d.shared_with);
  }
  if (d.done) {
    const size_t named = d.names.empty() ? r.bands.size() : d.names.size();
    for (size_t b = 0; b < d.noise.size() && b < named; ++b)
      if (d.noise[b] >= 0)
        std::printf(" %s %.2g%%", (d.names.empty() ? r.bands[b].name : d.names[b]).c_str(), 100 * d.noise[b]);
    std::printf("; memory %.3g MiB kept, %.3g MiB while baking%s\n", d.field_bytes / 1048576.0,
                d.work_bytes / 1048576.0, d.capped ? " (some photons stopped at the order cap)" : "");
  } else if (r.multiple_scattering == "diffuse") {
    std::printf("  diffuse field: none (no scattering band or no star)\n");
  } else if (r.multiple_scattering == "none") {
    std::printf("  light scattered between %s: left out (render.multiple_scattering = \"none\")\n",
                r.axial ? "cells" : "voxels");
  }
  if (r.pyramid.size() <= 1 && r.multiple_scattering == "pyramid") std::printf("  pyramid levels: none\n");
}

// The spectral renderer's model: filters, method, basis (docs/spectral.md).
void print_spectral(const RunReport& r) {
  const SpectralReport& s = *r.spectral;
  std::printf("computed, and why:\n");
  for (const SpectralFilterReport& f : s.filters)
    std::printf("  filter %s: %.0f-%.0f nm, pivot %.1f nm, %d cubic segment(s), fit error %.2g of the peak\n",
                f.name.c_str(), f.from_nm, f.to_nm, f.pivot_nm, f.segments, f.fit_error);
  std::printf("  attenuation: %s over %.3f-%.3f um (%s law, R_V %g)\n",
              s.attenuation == "inverse" ? "C_T / lambda (the report's)" : "the extinction law", s.lo_um, s.hi_um,
              to_string(r.law), r.R_V);
  if (s.method == "double") {
    std::printf("  method: double integral, %d wavelength samples per voxel and star\n", s.wavelengths);
  } else if (s.method == "analytic") {
    std::printf("  method: analytic integral (Algorithm 1): one set of exponential-integral antiderivatives at each of %d breaks "
                "(the filters' measured rows) per voxel and star, shared by the filters\n",
                s.breaks);
  } else if (s.method == "preintegrated") {
    std::printf("  method: pre-integrated, the integral over wavelength tabulated per star and filter over optical "
                "paths 0-%g (one lookup per voxel, star and filter)\n",
                s.max_depth);
  } else {
    std::printf("  method: %s, %d basis element(s) (%s norm) fitted on optical paths 0-%g, table to %g; elements a =",
                s.method == "projection"    ? "projection"
                : s.method == "voxel_light" ? "voxel light (per-view pre-pass)"
                                            : "light-density basis",
                s.basis, s.norm.c_str(), s.fit_depth,
                s.max_depth);
    for (double a : s.elements) std::printf(" %.3g", a);
    std::printf("; largest family residual %.2g\n", s.basis_error);
  }
  std::printf("  %d number(s) per ray; model %.3g s, resolve %.3g s\n", s.accumulators, s.model_seconds,
              s.resolve_seconds);
  if (r.bake.done)
    std::printf("  bake: %zu star(s) x %llu voxels, %g s\n", r.bake.stars, (unsigned long long)r.bake.cells,
                r.bake.seconds);
  for (const TableReport& t : r.tables) {
    if (!t.warning.empty()) std::fprintf(stderr, "nebula: warning: %s\n", t.warning.c_str());
    std::printf("  table a=%g g=%g: %s %s (%.3g s); its entries' median standard error %.2g%% (%llu photons a "
                "row: --table-photons)\n",
                t.albedo, t.g, to_string(t.origin), t.path.c_str(), t.seconds, 100 * t.noise,
                (unsigned long long)t.photons_per_row);
  }
  if (s.table_nodes > 0) {
    std::printf(r.tables.empty() ? "  single scattering per voxel (thin-voxel HG, spectral.tables = false), taken at kappa ="
                                 : "  scattering per voxel through its table (multiple scattering inside it), read at kappa =");
    for (double k : s.node_kappa) std::printf(" %.3g", k);
    std::printf(" and interpolated in kappa between\n");
    if (!s.node_albedo.empty()) {
      std::printf("  albedo and g varying with wavelength ([spectral.dust]), at those attenuations:");
      for (size_t m = 0; m < s.node_albedo.size(); ++m) std::printf(" a %.3g g %.3g;", s.node_albedo[m], s.node_g[m]);
      std::printf(" each node %s\n", r.tables.empty() ? "in the thin-voxel limit" : "through its own table");
    }
    if (r.diffuse.done)
      std::printf("  light between voxels: the band renderer's diffuse field of each star alone (%zu field(s)), baked "
                  "at those attenuations (one band each, the star's light at its wavelength), per-view passes %.3g s; "
                  "below, times and photon counts of all of them, noise and memory of the first\n",
                  r.diffuse.stars, s.diffuse_view_seconds);
    print_multiple_scattering(r);
  } else {
    std::printf("  single scattering per voxel (thin-voxel HG, spectral.tables = false); no light between voxels\n");
  }
  if (s.emission_lines + s.emission_continua > 0)
    std::printf("  emission: %d line(s), %d continuum(s) ([[spectral.emission]])\n", s.emission_lines,
                s.emission_continua);
  else
    std::printf("  no emission\n");
}

void print_computed(const RunReport& r) {
  if (r.spectral) return print_spectral(r);
  std::printf("computed, and why:\n");
  for (const BandReport& b : r.bands)
    std::printf("  band %s: A/A_V %.4f (%s law, R_V %g, Bessell passband), albedo %g, g %g%s\n", b.name.c_str(),
                b.extinction_ratio, to_string(r.law), r.R_V, b.albedo, b.g,
                b.scatters ? "" : (r.truth ? " (no scattering)" : " (no scattering: no table)"));
  if (r.axial) {
    const AxialMapReport& a = *r.axial;
    std::printf("  map: %s, %d x %d texels of %g pc, %zu emission plane(s), height-map max %d, %g s\n",
                a.source.c_str(), a.nx, a.nr, a.texel_pc, a.emission_planes, a.height_max, a.build_seconds);
  }
  for (const TableReport& t : r.tables) {
    if (!t.warning.empty()) std::fprintf(stderr, "nebula: warning: %s\n", t.warning.c_str());
    std::printf("  table a=%g g=%g for %s: %s %s (%.3g s); its entries' median standard error %.2g%% (%llu photons "
                "a row)\n",
                t.albedo, t.g, joined(t.bands).c_str(), to_string(t.origin), t.path.c_str(), t.seconds, 100 * t.noise,
                (unsigned long long)t.photons_per_row);
  }
  if (r.truth) return;
  if (r.bake.done && r.bake.reused)
    std::printf("  bake: %zu star(s) x %llu voxels, reused (the grid and the stars' positions unchanged)\n",
                r.bake.stars, (unsigned long long)r.bake.cells);
  else if (r.bake.done)
    std::printf("  bake: %zu star(s)%s x %llu %s, %g s\n", r.bake.stars, r.axial ? " on the axis" : "",
                (unsigned long long)r.bake.cells, r.axial ? "texels" : "voxels", r.bake.seconds);
  else
    std::printf("  bake: skipped (no scattering band or no star)\n");
  if (r.axial) {
    std::printf("  memory: map and skip structures %.3g MiB, with depths and tables %.3g MiB (%s)\n",
                r.axial->map_bytes / 1048576.0, r.axial->render_bytes / 1048576.0,
                r.backend == Backend::Cuda ? "on the GPU" : "host");
    print_multiple_scattering(r);
    return;
  }
  std::printf("  emission: %s\n", r.emission ? "per band grid" : "none in the scene");
  print_multiple_scattering(r);
  for (size_t j = 1; j < r.pyramid.size(); ++j) {
    const PyramidLevelReport& p = r.pyramid[j];
    std::printf("  pyramid level %d: grid %dx%dx%d (voxel %g pc), image %dx%d; build %.3f s, bake %.3f s, render %.3f s, "
                "%llu lookups beyond tau_max\n",
                p.level, p.shape.nx, p.shape.ny, p.shape.nz, p.shape.voxel, p.width, p.height, p.pyramid_seconds,
                p.bake_seconds, p.render_seconds, (unsigned long long)p.table_clamps);
  }
}

}  // namespace

void print_report(const RunReport& r) {
  print_headline(r);
  print_computed(r);
  if (r.truth) {
    const TruthReport& t = *r.truth;
    const double s = r.render_seconds;
    if (t.axial_grid.nx > 0)
      std::printf("  axial map traced voxelized in its own frame: %dx%dx%d voxels of %g pc (--axial-voxels), each the "
                  "mean of its texels\n",
                  t.axial_grid.nx, t.axial_grid.ny, t.axial_grid.nz, t.axial_grid.voxel);
    std::printf("  paths %llu, collisions (path vertices) %llu, tentative collisions %llu, capped %llu\n",
                (unsigned long long)t.paths, (unsigned long long)t.counters.vertices,
                (unsigned long long)t.counters.tentative, (unsigned long long)t.counters.capped);
    std::printf("  tracing %.3f s: %.3g vertices/s, %.3g paths/s, %.3g spp/s at this size; total %.2f s\n", s,
                t.counters.vertices / s, t.paths / s, t.spp / s, r.total_seconds);
    return;
  }
  char star_pixels[160] = "";
  if (r.star_pixel_rays > 0)
    std::snprintf(star_pixels, sizeof star_pixels,
                  " (the %d pixels at the stars' images in %d cells, %d rays: render.star_pixels)", r.star_pixels,
                  r.star_pixel_cells, r.star_pixel_rays);
  if (r.spectral) {
    std::printf("render: %.3f s marching%s; total %.2f s\n", r.render_seconds, star_pixels, r.total_seconds);
    return;
  }
  std::printf("render: %.3f s marching%s, %llu table lookups beyond tau_max (clamped); total %.2f s\n",
              r.render_seconds, star_pixels, (unsigned long long)r.table_clamps, r.total_seconds);
}

}  // namespace nebula::app
