// The spectral renderer on a scene ([spectral], docs/spectral.md): the bands'
// filters fitted, the stars' black bodies, the scene's extinction law as a
// function of wavelength; one V-band depth bake per star; the spectral march
// (spectral/) and the resolve into one plane per filter.
#include <chrono>
#include <string>

#include "core/error.h"
#include "illumination/optical_depth_bake.h"
#include "pipeline/render_scene.h"
#include "pipeline/run_setup.h"
#include "pipeline/spectral_scene.h"
#include "pipeline/table_source.h"
#include "spectral/spectral_renderer.h"

namespace nebula {

using namespace pipeline_detail;

namespace {

spectral::SpectralMethod method_of(const std::string& name) {
  if (name == "double") return spectral::SpectralMethod::Double;
  if (name == "analytic") return spectral::SpectralMethod::Analytic;
  if (name == "light_density") return spectral::SpectralMethod::LightBasis;
  if (name == "voxel_light") return spectral::SpectralMethod::VoxelLight;
  return spectral::SpectralMethod::Projection;
}

}  // namespace

spectral::SpectralSettings spectral_settings(const Scene& scene) {
  if (!scene.spectral) throw Error(scene.path + ": spectral: the scene has no [spectral] table");
  const SpectralSpec& p = *scene.spectral;
  spectral::SpectralSettings s;
  s.method = method_of(p.method);
  s.basis = p.basis;
  s.wavelengths = p.wavelengths;
  s.attenuation = p.attenuation == "inverse" ? spectral::Attenuation::Inverse : spectral::Attenuation::Law;
  s.R_V = scene.dust.R_V;
  s.law = scene.dust.law;
  s.relative = p.norm == "relative";
  s.fit_depth = p.fit_depth;
  s.max_depth = p.max_depth;
  s.near_voxels = p.near_voxels;
  s.lo_um = p.range_lo_um;
  s.hi_um = p.range_hi_um;
  s.table_nodes = p.tables ? p.table_nodes : 0;
  return s;
}

RenderOutput render_spectral_scene(const Scene& scene, const RenderOptions& o) {
  if (!scene.spectral) throw Error(scene.path + ": spectral: the scene has no [spectral] table");
  validate_scene(scene);
  check_run_memory(scene, RunKind::Fast);
  const SceneBands bands = scene_bands(scene);
  RunReport report = begin_report(scene, bands, "spectral", o.backend);
  report.mode = "spectral " + scene.spectral->method;
  report.multiple_scattering = "none";

  // The voxels' scattering table for the dust's (albedo, g): the scene's file or
  // the cached one (generated on first use), as the band renderer takes it.
  std::shared_ptr<const ScatteringTable> table;
  if (scene.spectral->tables) {
    BandTables tables = resolve_tables(scene, {o.backend, o.table_photons, o.progress});
    for (const auto& t : tables.per_band)
      if (t) {
        table = t;
        break;
      }
    report.tables = tables.report;
  }

  // The model: filters as piecewise cubics, basis and tables (host).
  const auto t_model = std::chrono::steady_clock::now();
  std::vector<std::pair<std::string, Passband>> filters;
  for (size_t b = 0; b < scene.bands.size(); ++b) filters.push_back({scene.bands[b], bands.filters[b]});
  std::vector<spectral::SpectralStar> stars;
  for (const SceneStar& s : scene.stars) stars.push_back({s.temperature_K});
  const spectral::SpectralSettings settings = spectral_settings(scene);
  std::vector<spectral::SpectralEmission> emission;
  for (const SpectralEmissionSpec& e : scene.spectral->emission)
    emission.push_back({e.line_nm / 1000.0, e.continuum, e.lo_nm / 1000.0, e.hi_nm / 1000.0});
  spectral::SpectralModel model;
  try {
    model = spectral::build_spectral_model(filters, stars, settings, emission);
  } catch (const Error& e) {
    throw Error(scene.path + ": " + e.what());  // "spectral: <reason>"
  }
  SpectralReport sr;
  sr.method = scene.spectral->method;
  sr.basis = model.basis.size();
  sr.wavelengths = settings.wavelengths;
  sr.attenuation = scene.spectral->attenuation;
  sr.norm = scene.spectral->norm;
  sr.lo_um = model.lo_um;
  sr.hi_um = model.hi_um;
  sr.fit_depth = model.fit_depth;
  sr.max_depth = model.max_depth;
  sr.elements = model.element_depth;
  sr.basis_error = model.basis.error.empty() ? 0.0 : model.basis.error.back();
  sr.accumulators = model.planes();
  for (const spectral::SpectralEmission& e : model.emission) ++(e.line_um > 0 ? sr.emission_lines : sr.emission_continua);
  sr.table_nodes = table ? settings.table_nodes : 0;
  sr.node_kappa = table ? model.node_kappa : std::vector<double>{};
  for (size_t b = 0; b < filters.size(); ++b)
    sr.filters.push_back({filters[b].first, filters[b].second.wavelength_nm.front(),
                          filters[b].second.wavelength_nm.back(), pivot_wavelength_nm(filters[b].second),
                          model.fits[b].segments, model.fits[b].max_error});
  sr.model_seconds = seconds_since(t_model);

  // One V-band depth bake per star (the spectral march scales it by kappa(lambda)).
  std::vector<Vec3> positions;
  for (const SceneStar& s : scene.stars) positions.push_back(s.position);
  BakeResult bake;
  if (!positions.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    bake = bake_star_depths(scene.density, positions, o.backend);
    report.bake = {true, positions.size(), scene.density.shape.count(), seconds_since(t0)};
  }

  spectral::SpectralRenderInputs in;
  in.density = &scene.density;
  in.model = &model;
  for (size_t k = 0; k < scene.stars.size(); ++k)
    in.lights.push_back({scene.stars[k].position, scene.stars[k].luminosity_lsun, &bake.tau_v[k]});
  in.albedo = float(scene.dust.albedo.front());
  in.g = float(scene.dust.g.front());
  in.table = table.get();
  for (size_t c = 0; c < emission.size(); ++c) {
    const auto& grids = scene.spectral->emission_grids;  // scale applied; none: the voxel's tau_V times scale
    const std::vector<float>* grid = c < grids.size() && !grids[c].empty() ? &grids[c] : nullptr;
    in.emission.push_back({grid, grid ? 1.0f : float(scene.spectral->emission[c].scale)});
  }
  in.camera = make_camera(scene.camera);
  double march_seconds = 0;
  const Image acc = spectral::render_spectral(in, o.backend, &march_seconds);
  const auto t_resolve = std::chrono::steady_clock::now();
  RenderOutput out;
  out.image = spectral::resolve_filters(acc, model);
  sr.resolve_seconds = seconds_since(t_resolve);
  report.render_seconds = march_seconds;
  report.spectral = sr;
  draw_scene_stars(scene, bands, in.camera, 1.0, out.image);

  out.report = report;
  out.metadata = scene_metadata(scene, bands, scene.camera, report.mode);
  out.metadata.entries.push_back(
      {"multiple_scattering", table ? "inside voxels (tables), none between them (spectral renderer)"
                                    : "none (spectral renderer: thin-voxel single scattering)"});
  out.metadata.entries.push_back({"spec_nodes", sr.table_nodes});
  out.metadata.entries.push_back({"spec_emission", int(emission.size())});
  out.metadata.entries.push_back({"spec_method", sr.method});
  out.metadata.entries.push_back({"spec_basis", sr.basis});
  out.metadata.entries.push_back({"spec_atten", sr.attenuation});
  out.metadata.entries.push_back({"spec_norm", sr.norm});
  out.metadata.entries.push_back({"spec_lo_um", sr.lo_um});
  out.metadata.entries.push_back({"spec_hi_um", sr.hi_um});
  out.metadata.entries.push_back({"spec_fit_tau", sr.fit_depth});
  out.metadata.entries.push_back({"spec_max_tau", sr.max_depth});
  if (sr.method == "double") out.metadata.entries.push_back({"spec_samples", sr.wavelengths});
  return out;
}

}  // namespace nebula
