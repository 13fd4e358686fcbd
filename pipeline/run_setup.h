#pragma once
// Internal to pipeline/: what every renderer's run derives from the scene the
// same way (the start of its report, the image metadata, drawn stars).
#include <chrono>
#include <memory>
#include <string>

#include "core/camera.h"
#include "core/image.h"
#include "diffuse/diffuse_bake.h"
#include "imageio/image_output.h"
#include "pipeline/run_report.h"
#include "pipeline/scene_bands.h"
#include "pipeline/table_source.h"
#include "scene/scene.h"

namespace nebula {
struct RenderOptions;
class Progress;
}  // namespace nebula

namespace nebula::pipeline_detail {

inline double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// The scene, the camera and the bands; `scatters` per band (empty: every band
// with albedo > 0).
RunReport begin_report(const Scene& scene, const SceneBands& bands, const std::string& renderer, Backend backend,
                       const std::vector<bool>& scatters = {});

// What the star bakes depend on: the grid (by what it was made from; a scene
// built in code has no such text and gets "", which never reuses), the
// stars' positions and the backend. Equal keys, equal bakes.
std::string star_bake_key(const Scene& scene, Backend backend);

// The unit of every rendered image: radiance per band, in a form FITS and
// astropy.units parse (docs/image_files.md).
inline const char* const kRadianceUnit = "solLum pc-2 sr-1";
inline const char* const kRadianceVarianceUnit = "solLum2 pc-4 sr-2";

// The FITS world coordinates of the camera (CTYPE, CRPIX, ...): offsets in pc
// for the orthographic camera, angles from the view axis (TAN, ARC) for the
// perspective and fisheye cameras (docs/image_files.md).
MetaEntries camera_wcs(const CameraSettings& camera);
// A band as per-band metadata keys name it (pivot_nm_<key>, albedo_<key>,
// star1_P_<key>, ...): its name when at most kBandKeyLength characters, else
// "b" and its plane number from 1 ("b2"): numeric keys have at most 14
// characters (imageio/image_output.h), and "pivot_nm_" takes 9 of them.
constexpr size_t kBandKeyLength = 5;
std::string band_key(const std::vector<std::string>& bands, size_t b);

// sqrt(integral T lambda / integral T / lambda), nm.
double pivot_wavelength_nm(const Passband& passband);

// Units, the camera's exposure, its world coordinates and settings, the date,
// the software and commit, per-band pivot wavelength, albedo, g and extinction
// ratio, R_V, the stars with their band powers, the scene file and its
// resolved text, and the render mode.
ImageMetadata scene_metadata(const Scene& scene, const SceneBands& bands, const CameraSettings& camera,
                             const std::string& mode);

// The scene's stars drawn as attenuated point sources when output.draw_stars
// is set (raycast/point_stars.h), for 3D grids.
void draw_scene_stars(const Scene& scene, const SceneBands& bands, const Camera& camera, double exposure,
                      Image& image);

// The diffuse bake's bands (albedo 0 where a band has no table) and options
// (render.diffuse_*), the same for 3D grids and axial maps.
std::vector<DiffuseBand> diffuse_bands(const SceneBands& bands, const BandTables& tables);
DiffuseBakeOptions diffuse_options(const Scene& scene);
// The report's account of a finished bake (wall: its whole time).
DiffuseReport diffuse_report(const std::vector<DiffuseBand>& bands, const DiffuseBakeOptions& options,
                             const DiffuseField& field, int voxels_per_cell, const DiffuseBakeStats& stats,
                             double wall_seconds);
// What an image's light between voxels (or cells) came from, for its metadata.
std::string multiple_scattering_text(const RunReport& r);

// The report's count of the star pixels a frame of `camera` marches with
// many rays each around stars at these positions (illumination/star_pixels.h).
void report_star_pixels(const Camera& camera, const std::vector<Vec3>& stars, RunReport& report);

// Pixel-area sampling for the fast renderers (render.samples_per_pixel =
// k^2): they trace the frame at k times the resolution, a k x k grid of
// sub-pixel rays at the centres of equal strata, and each pixel is the mean
// of its k^2 rays. supersampled_camera is that finer camera (k = 1: the same).
CameraSettings supersampled_camera(const CameraSettings& camera, int samples_per_pixel);
// The mean of each k x k block of `fine` (k * width x k * height).
Image box_downsample(Image fine, int k);  // k = 1: `fine` itself, moved (no copy)
// A progress bar over the bake's photons on the CPU (null otherwise).
std::unique_ptr<Progress> diffuse_progress(const std::vector<DiffuseBand>& bands, const DiffuseBakeOptions& options,
                                           const RenderOptions& o);

}  // namespace nebula::pipeline_detail
