#pragma once
// The scene model the renderer consumes: density (and optional emission)
// grids, dust parameters per band, stars, one camera and the output. Built
// by load_scene (scene/scene_file.h) from a TOML file, or by demo_scene().
//
// Units (docs/scene.md): lengths in parsecs (grid origin and voxel edge,
// star positions, camera); luminosity in solar luminosities; temperatures in
// K. Rendered radiance is in L_sun pc^-2 sr^-1 per band times `exposure`, a
// relative scale (no distance to the observer, no detector).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/display.h"
#include "core/grid.h"
#include "core/vec3.h"
#include "diffuse/diffuse_taper.h"
#include "illumination/extinction.h"
#include "scene/camera_path.h"
#include "illumination/passband.h"

namespace nebula {

// Dust optical properties, one entry per scene band (Scene::bands order).
struct DustParams {
  std::vector<double> albedo;  // a_b in [0, 1]; default 0.6 in every band
  std::vector<double> g;       // HG asymmetry g_b, |g| < 1; default 0.6
  double R_V = 5.0;            // total-to-selective extinction, [2, 6]
  ExtinctionLaw law = ExtinctionLaw::CCM89;
  // Scattering table file per band; an empty string means "generate on first
  // use and cache by (albedo, g)" (done by the renderer, not here). Non-empty
  // names are resolved against the scene file's folder and exist.
  std::vector<std::string> table_files;
};

// The brightest star a scene may hold (L_sun): about a galaxy's light. Radiance
// is single precision; this bound and the camera's exposure bound
// (kMaxCameraExposure) keep every pixel finite.
constexpr double kMaxLuminosityLsun = 1e12;

struct SceneStar {
  std::string name;
  Vec3 position;           // parsecs, same frame as the grid
  double luminosity_lsun;  // bolometric, L_sun, > 0
  double temperature_K;    // effective temperature; from spectral_class if given
  std::string spectral_class;  // as written in the scene ("" when only a temperature was given)
};

// The scene's camera is the one camera model (core/camera.h): CameraSettings,
// with a scene file's defaults: up = +z (a scene file's [camera] table).
CameraSettings scene_camera_defaults();

// An axial-symmetric nebula ([axial] in a scene file, docs/scene.md): a 2D
// map M(x, r) rotated about an axis, given instead of [density]. The scene
// holds where the map comes from; the pipeline builds it
// (pipeline/axial_map_source.h) and renders it with axial/axial_renderer.h.
// A deformation's noise ([axial.colour_deform] or [axial.shape_deform],
// docs/scene.md; axial/axial_deform.h). Present in the file: on.
struct AxialNoiseSpec {
  bool on = false;
  std::string kind = "fbm";   // simplex, fbm, turbulence, cellular
  double frequency = 4.0;     // features per map length
  int octaves = 4;            // 1 to 8 (fbm, turbulence, cellular)
  double gain = 0.5;          // (0, 1]
  double lacunarity = 2.0;    // >= 1
  double amplitude = 0.5;     // colour: largest lowering [0, 1]; shape: largest pull [0, 0.9]
  uint32_t seed = 1;
};

struct AxialSpec {
  std::string source;              // "synthetic", "file" (HDF5) or "image"
  std::string synthetic;           // bipolar, lopsided, shells, empty, full
  std::string path;                // file or image, resolved against the scene's folder
  std::string dataset = "tau_v";   // file: the 2D dataset [nr][nx]
  std::string emission_prefix;     // file: emission datasets <prefix><band>; "" = none
  std::string tau_channel = "tau_v";           // image: the band (channel) holding tau_v
  std::vector<std::string> emission_channels;  // image: per scene band, "" = none
  int nx = 1024, nr = 512;         // synthetic: texels along the axis and radially
  double length_pc = 2.0;          // the map's length along the axis; texel = length_pc / nx
  double tau_scale = 1.0;          // multiplies tau_v
  double emission_scale = 1.0;     // multiplies emission (0: none)
  Vec3 origin{0, 0, 0};            // the axis point where the map starts (x = 0)
  Vec3 axis{0, 0, 1};              // unit direction of +x
  std::string skip = "distance";
  double step_texels = 0.5;        // the march's step h in texels
  AxialNoiseSpec colour_deform;    // [axial.colour_deform]: lowers emission and extinction per band
  AxialNoiseSpec shape_deform{false, "fbm", 4.0, 4, 0.5, 2.0, 0.2, 1};  // [axial.shape_deform]: pulls samples towards the axis
};

// How the fast renderer adds light scattered between voxels (the tables hold
// the scattering inside each voxel): the diffuse field baked by photons
// (diffuse/, docs/diffuse.md), the 2005 paper's resolution pyramid
// (docs/pyramid.md), or not at all.
enum class MultipleScattering { Diffuse, Pyramid, None };
const char* to_string(MultipleScattering mode);  // "diffuse", "pyramid", "none"
bool parse_multiple_scattering(const std::string& name, MultipleScattering& out);

// The diffuse field's settings ([render] diffuse_*, docs/scene.md).
struct DiffuseSettings {
  // Harmonics' degree, 0 to 4; kOrderAuto: 4, or 3 where zonal degrees carry
  // the stars' light (resolved_order).
  static constexpr int kOrderAuto = -1;
  int order = kOrderAuto;
  int cells = 64;                // field cells along the grid's longest axis (at least)
  // Zonal degrees of the brightest stars' light (docs/diffuse.md): 0 none,
  // else order + 1 to 32; kZonalAuto: 24 when a band's g >= 0.8, else none.
  static constexpr int kZonalAuto = -1;
  int zonal = kZonalAuto;
  uint64_t photons = 1u << 20;   // per band
  uint64_t seed = 1;
  DiffuseTaper taper = DiffuseTaper::Auto;  // the response's (docs/diffuse.md, "Truncation"; resolved_taper)
};

// The zonal degree a scene's field uses (resolving "auto" by the bands' g).
int resolved_zonal(const DiffuseSettings& d, const std::vector<double>& g);
// The harmonics' degree a scene's field uses (resolving "auto" likewise).
int resolved_order(const DiffuseSettings& d, const std::vector<double>& g);

// A filter read from a file the scene names ([filters] in a scene file): a
// band like the built-in filters (illumination/filters.h).
struct SceneFilter {
  std::string name;   // as `bands` names it
  std::string path;   // resolved against the scene's folder
  Passband passband;  // illumination/filter_file.h
};

// The spectral renderer ([spectral] in a scene file; docs/scene.md,
// docs/spectral.md): every band integrated over wavelength through its filter
// (Barres 2023) instead of the band renderer's one extinction ratio and star
// power per band. Each voxel scatters the stars' light through its scattering
// table (multiple scattering inside the voxel) read at a few attenuations;
// emission as lines and continua; no light between voxels yet.
// One emission component of the spectral renderer ([[spectral.emission]];
// docs/scene.md): j(x, lambda) = w(x) phi(lambda), added to a ray crossing
// the voxel along one voxel edge. w: the HDF5 dataset `dataset` of `file`
// (the density's shape), or the voxel's tau_V when no file is given, times
// `scale`. phi: a line (a Dirac spike at line_nm; w in L_sun pc^-2 sr^-1) or
// a continuum, the polynomial sum_k c_k lambda^k (lambda in um; w phi in
// L_sun pc^-2 sr^-1 um^-1) on [lo_nm, hi_nm], zero outside.
struct SpectralEmissionSpec {
  double line_nm = 0;               // > 0: a line
  std::vector<double> continuum;    // else: the polynomial's coefficients c_0, c_1, ...
  double lo_nm = 0, hi_nm = 0;      // the continuum's range; 0: the basis' wavelength range
  std::string file, dataset;        // the weight grid (resolved path), or "" for tau_V
  double scale = 1;
};
constexpr int kMaxSpectralEmission = 8;

struct SpectralSpec {
  std::string method = "projection";  // double, analytic, projection, light_density, voxel_light
  int basis = 4;                      // elements of the greedy basis, 1..16
  int wavelengths = 20;               // double: wavelength samples, 2..4096
  std::string attenuation = "law";    // law (dust.law, dust.R_V) or inverse (C_T / lambda, the report's)
  std::string norm = "relative";      // relative (ours) or absolute (the report's)
  double fit_depth = 0;               // V-band optical paths the basis is fitted on; 0: automatic (8)
  double max_depth = 0;               // the coefficient table's range; 0: automatic
  double near_voxels = 10;            // voxel_light: pairs this close to a star (in voxels) taken exactly
  double range_lo_um = 0, range_hi_um = 0;  // the basis' wavelength range; 0: the bands' span
  bool tables = true;                 // the voxel's table P(a tau_V kappa, mu); false: the thin limit tau_sct p_HG
  int table_nodes = 3;                // attenuations kappa at which the table is read, 1..4
  // [spectral.dust]: albedo and g at these wavelengths (nm, increasing; linear
  // between, constant beyond); empty: dust.albedo and dust.g at every
  // wavelength. A curve left out holds the dust's constant at every point.
  std::vector<double> dust_nm, dust_albedo, dust_g;
  std::vector<SpectralEmissionSpec> emission;  // [[spectral.emission]]
  // One weight grid per component, scale applied (empty for tau_V weights).
  std::vector<std::vector<float>> emission_grids;
};

// A file a scene reads: the key that names it ("scene" for the scene file
// itself) and the path as resolved. Front ends refuse to write over any of them.
struct SceneInput {
  std::string key, path;
};

struct Scene {
  std::string path;  // the scene file as given ("demo" for demo_scene())
  // The scene file's TOML after the overrides, as toml++ prints it (empty
  // for a scene built in code): what images record as their scene.
  std::string resolved_toml;
  std::vector<SceneInput> inputs;  // every file the scene reads (load_scene fills it)
  // What the density and emission grids were made from, as text (load_scene
  // fills it; empty for a scene built in code): equal texts, equal grids.
  std::string grid_source;
  std::vector<std::string> bands{"B", "V", "R"};
  std::vector<SceneFilter> filters;        // user filters the bands may name
  std::optional<SpectralSpec> spectral;    // set: render with the spectral renderer
  DensityGrid density;  // tau_v per voxel (empty for an axial scene)
  std::optional<AxialSpec> axial;  // set instead of a density grid
  // Empty, or one grid per band (bands order) with the density's shape: the
  // radiance j a ray gains crossing the voxel along one voxel edge
  // (L_sun pc^-2 sr^-1; DESIGN.md section 3).
  std::vector<std::vector<float>> emission;
  double density_scale = 1.0;   // [density] scale, already applied to `density`
  double emission_scale = 1.0;  // [emission] scale, already applied to `emission`
  DustParams dust;
  std::vector<SceneStar> stars;
  CameraSettings camera = scene_camera_defaults();
  std::optional<CameraPath> camera_path;  // [animation]: keyframes for `nebula animate`
  DisplaySettings display;                // [display]: how PNGs and the viewer show radiance
  std::string output = "nebula.exr";  // as written; relative to the working directory
  bool draw_stars = false;
  double star_psf_pixels = 1.5;  // Gaussian sigma of a drawn star, pixels
  // Light scattered between voxels: by default the diffuse field; with pyramid
  // levels (render.levels > 0) and no explicit choice, the pyramid.
  MultipleScattering multiple_scattering = MultipleScattering::Diffuse;
  DiffuseSettings diffuse;
  // Coarser levels of the multi-resolution pyramid (2005 paper, section 4.2),
  // for multiple_scattering = Pyramid; at most the grid allows
  // (multires/volume_pyramid.h), checked by the renderer.
  int pyramid_levels = 0;
  // Rays per pixel ([render] samples_per_pixel): k x k stratified over the
  // pixel's area, so a pixel is its area's mean, not its centre's value (the
  // 1/d cusp next to a star). A square in 1..kMaxSamplesPerPixel.
  int samples_per_pixel = 1;
  // The pixels at each star's image marched with many rays each ([render]
  // star_pixels; illumination/star_pixels.h): their light changes within a
  // pixel (1/d, the phase's forward peak). Off: one ray each.
  bool star_pixels = true;
};

constexpr int kMaxSamplesPerPixel = 256;
// k for samples_per_pixel = k^2 (the rounded square root; check the square).
inline int samples_per_pixel_side(int n) {
  int k = 1;
  while ((k + 1) * (k + 1) <= n) ++k;
  return k;
}

// Checks a Scene built in code (load_scene checks the same rules and more):
// bands, per-band vector sizes, albedo, g, R_V, stars, camera, output, grid
// shape, emission sizes and values. Throws Error "<scene.path>: <key>: <reason>"
// with the key named as in the scene file.
void validate_scene(const Scene& scene);

}  // namespace nebula
