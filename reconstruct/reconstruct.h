#pragma once
// Reconstruction of an axial map from one image (Khalass 2021, section 3.3;
// docs/axial.md, "Reconstruction"). The image shows the nebula at the
// thesis' inclination 0: its symmetry axis lies in the image plane, at the
// point and angle given. The image is resampled into the axis' frame (one
// pixel per texel), the two sides of the axis averaged, and every image
// column fitted, per band, by the map column the renderer turns into it:
//   powell  the thesis' analysis by synthesis (powell_column.h), CPU or CUDA;
//   nnls    ours: exact non-negative least squares per column (column_nnls.h);
//   absorb  ours: emission and extinction together, a bounded nonlinear least-
//           squares fit (Ceres) started from the nnls answer (absorb_fit.h,
//           its own library so that Ceres stays out of the GPU tests).
#include <string>
#include <vector>

#include "axial/axial_map.h"
#include "core/backend.h"
#include "core/image.h"
#include "reconstruct/powell_column.h"

namespace nebula {

struct ColumnProjection;  // reconstruct/projection.h

enum class ReconstructMethod { Powell, Nnls, Absorb };
const char* to_string(ReconstructMethod m);  // "powell", "nnls", "absorb"
// Error "<option>: '<text>' is not a method (known: powell, nnls, absorb)".
ReconstructMethod parse_reconstruct_method(const std::string& text, const std::string& option);

// Where the symmetry axis lies in the image: the point where the map starts
// (x = 0), in pixels from the image's top-left corner (pixel (px, py) spans
// [px, px + 1) x [py, py + 1)), and the direction of +x, counter-clockwise
// from the image's rightward direction as the image is seen.
struct ImageAxis {
  double x = 0, y = 0;
  double angle_deg = 0;
};

// The image in the axis' frame: nx columns along the axis, nr rows on each
// side (texel = pixel). `profile` holds, per band, column and distance j
// (texel j's centre at j + 0.5 from the axis), the mean of the two sides;
// `side_rms` the RMS of half their difference over everything, the noise an
// axisymmetric image shows (0 without noise).
struct StraightImage {
  int nx = 0, nr = 0;
  std::vector<std::string> bands;
  std::vector<float> profile;  // [band][ix][j]
  double side_rms = 0;
  const float* column(int band, int ix) const { return profile.data() + (size_t(band) * nx + ix) * nr; }
};

// Bilinear samples of `image` at the axis frame's texel centres. `length`
// and `radius` in texels (= pixels), 0: as far as the image reaches (every
// sample inside it). Errors name "axis", "length" or "radius": a point off
// the image, an axis leaving it at once, a length or radius past its edge, a
// pixel that is not finite.
StraightImage straighten_image(const Image& image, const ImageAxis& axis, int length = 0, int radius = 0);

struct ReconstructSettings {
  ReconstructMethod method = ReconstructMethod::Nnls;
  ImageAxis axis;
  int length = 0, radius = 0;  // texels; 0: as far as the image reaches
  double smoothness = 0;       // Tikhonov weight (nnls, absorb; column_nnls.h); < 0: choose_smoothness
  float step_texels = 0.5f;    // the march step the forward model uses (the scene's axial.step_texels)
  Backend backend = Backend::Cpu;  // powell: cpu or cuda; nnls and absorb run on the CPU
  PowellSettings powell;
  std::vector<float> extinction_ratio;  // absorb: A_b / A_V per image band; empty: 1 for every band
};

struct ReconstructReport {
  int nx = 0, nr = 0, bands = 0;
  double seconds_projection = 0;  // rendering the forward model's matrix
  double seconds_solve = 0;       // the fits of every column
  double image_error = 0;         // The discrepancy principle: the Tikhonov weight whose NNLS fit leaves a
// residual RMS per pixel equal to the noise the two sides show
// (StraightImage::side_rms), by bisection of its logarithm on up to 64
// columns; 0 for an image whose sides agree. Asymmetry of the nebula itself
// counts as noise here, so the weight is an upper estimate.
double choose_smoothness(const ColumnProjection& projection, const StraightImage& image);

// ||model - input|| / ||input|| over the straightened image
  double side_rms = 0;            // StraightImage::side_rms
  double side_difference = 0;     // ColumnProjection::side_difference
  double smoothness = 0;          // the weight used (chosen when the settings' was < 0)
  long long iterations = 0;       // Powell sweeps, NNLS pivoting steps or Ceres iterations, summed over columns
  int not_converged = 0;          // columns whose solver stopped at its iteration limit
};

// The map (texel 1, origin 0, axis +x; emission per image band in its
// order, tau_v 0 unless method absorb) and the report.
AxialMap reconstruct_axial_map(const StraightImage& image, const ReconstructSettings& s,
                               ReconstructReport* report = nullptr);
AxialMap reconstruct_axial_map(const Image& image, const ReconstructSettings& s, ReconstructReport* report = nullptr);
// The same with the forward model's matrix given (built for image.nr texels
// with s.step_texels; benchmarks build it once).
AxialMap reconstruct_axial_map(const StraightImage& image, const ReconstructSettings& s,
                               const ColumnProjection& projection, ReconstructReport* report = nullptr);

// The discrepancy principle: the Tikhonov weight whose NNLS fit leaves a
// residual RMS per pixel equal to the noise the two sides show
// (StraightImage::side_rms), by bisection of its logarithm on up to 64
// columns; 0 for an image whose sides agree. Asymmetry of the nebula itself
// counts as noise here, so the weight is an upper estimate.
double choose_smoothness(const ColumnProjection& projection, const StraightImage& image);

// ||model - input|| / ||input|| over the straightened image: the emitting
// model A e, or with extinction ratios given, the renderer's image of each
// column with the map's tau_v (column_model.h: rendered_column).
double model_image_error(const ColumnProjection& projection, const StraightImage& image, const AxialMap& map,
                         const std::vector<float>& ratio, float step_texels);

// Powell on the GPU: one block per (column, band), `profiles` count columns of
// n values; returns count columns of n values (the map columns). Sweeps
// summed into *sweeps. Throws without CUDA.
std::vector<float> powell_columns_cuda(const ColumnProjection& projection, const std::vector<float>& profiles,
                                       int count, const PowellSettings& settings, long long* sweeps);

// The map as the HDF5 file `[axial] file = ...` reads (docs/scene.md):
// datasets tau_v and <emission_prefix><band> ([nr][nx], float32). Written
// aside and renamed (core/atomic_file.h); refuses an existing file unless
// `overwrite`.
void write_axial_map_hdf5(const AxialMap& map, const std::vector<std::string>& bands, const std::string& path,
                          bool overwrite, const std::string& emission_prefix = "emission_");

}  // namespace nebula
