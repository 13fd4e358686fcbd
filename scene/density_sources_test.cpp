#include "scene/density_sources.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <sys/resource.h>

#include "scene/test_files.h"

namespace nebula {
namespace {

using testing::expect_error;
using testing::FitsKeys;
using testing::H5Dataset;
using testing::write_fits;
using testing::write_h5;

// Distinct values per voxel: 100 z + 10 y + x (+ 0.25 to be non-integral).
std::vector<double> distinct_values(int nx, int ny, int nz) {
  std::vector<double> v;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) v.push_back(100.0 * z + 10.0 * y + x + 0.25);
  return v;
}

class DensityFiles : public testing::TempDirTest {};

// ------------------------------------------------------------ HDF5

TEST_F(DensityFiles, Hdf5RoundTripKeepsValuesShapeVoxelAndOrigin) {
  const int nx = 5, ny = 4, nz = 3;
  H5Dataset set;
  set.dims = {hsize_t(nz), hsize_t(ny), hsize_t(nx)};
  set.values = distinct_values(nx, ny, nz);
  set.voxel_size = 0.02;
  set.origin = std::vector<double>{1.0, -2.0, 3.5};
  write_h5(path("cloud.h5"), {set});
  const DensityGrid g = load_density_hdf5(path("cloud.h5"));
  EXPECT_EQ(g.shape.nx, nx);
  EXPECT_EQ(g.shape.ny, ny);
  EXPECT_EQ(g.shape.nz, nz);
  EXPECT_FLOAT_EQ(g.shape.voxel, 0.02f);
  EXPECT_FLOAT_EQ(g.shape.origin.x, 1.0f);
  EXPECT_FLOAT_EQ(g.shape.origin.y, -2.0f);
  EXPECT_FLOAT_EQ(g.shape.origin.z, 3.5f);
  ASSERT_EQ(g.tau_v.size(), size_t(nx * ny * nz));
  for (size_t i = 0; i < g.tau_v.size(); ++i) EXPECT_EQ(g.tau_v[i], float(set.values[i]));
  // x is the fastest axis: voxel (x=4, y=2, z=1) holds 100 + 20 + 4.
  EXPECT_EQ(g.tau_v[g.shape.index(4, 2, 1)], 124.25f);
}

TEST_F(DensityFiles, Hdf5ReadsOtherTypesAndRootAttributes) {
  H5Dataset set;
  set.name = "dust";
  set.dims = {2, 2, 2};
  set.values = {0, 1, 2, 3, 4, 5, 6, 7};
  set.file_type = H5T_STD_I16LE;
  write_h5(path("ints.h5"), {set}, 0.5);  // voxel_size on the root group
  const DensityGrid g = load_density_hdf5(path("ints.h5"), "dust");
  EXPECT_FLOAT_EQ(g.shape.voxel, 0.5f);
  EXPECT_EQ(g.shape.origin.x, 0.0f);
  EXPECT_EQ(g.tau_v[7], 7.0f);

  set.file_type = H5T_IEEE_F64LE;
  set.values[3] = 0.125;
  set.voxel_size = 0.25;  // the dataset's attribute wins over the root's
  write_h5(path("doubles.h5"), {set}, 0.5);
  const DensityGrid d = load_density_hdf5(path("doubles.h5"), "dust");
  EXPECT_FLOAT_EQ(d.shape.voxel, 0.25f);
  EXPECT_EQ(d.tau_v[3], 0.125f);
}

TEST_F(DensityFiles, Hdf5RefusesBadFiles) {
  H5Dataset good;
  good.dims = {2, 2, 2};
  good.values.assign(8, 1.0);
  good.voxel_size = 0.1;

  expect_error([&] { load_density_hdf5(path("absent.h5")); }, {"absent.h5", "cannot open"});
  write_text("text.h5", "not hdf5");
  expect_error([&] { load_density_hdf5(path("text.h5")); }, {"text.h5", "not an HDF5 file"});

  write_h5(path("other.h5"), {good});
  expect_error([&] { load_density_hdf5(path("other.h5"), "rho"); },
               {"other.h5", "'rho'", "not found", "tau_v"});

  H5Dataset flat = good;
  flat.dims = {2, 4};
  write_h5(path("flat.h5"), {flat});
  expect_error([&] { load_density_hdf5(path("flat.h5")); }, {"flat.h5", "tau_v", "3-D", "2-D"});

  H5Dataset no_voxel = good;
  no_voxel.voxel_size.reset();
  write_h5(path("novoxel.h5"), {no_voxel});
  expect_error([&] { load_density_hdf5(path("novoxel.h5")); }, {"novoxel.h5", "tau_v", "voxel_size"});

  for (double bad : {0.0, -0.1, std::numeric_limits<double>::infinity()}) {
    H5Dataset v = good;
    v.voxel_size = bad;
    write_h5(path("badvoxel.h5"), {v});
    expect_error([&] { load_density_hdf5(path("badvoxel.h5")); }, {"badvoxel.h5", "voxel_size"});
  }

  H5Dataset origin = good;
  origin.origin = std::vector<double>{1, 2};
  write_h5(path("origin.h5"), {origin});
  expect_error([&] { load_density_hdf5(path("origin.h5")); }, {"origin.h5", "origin", "3 values"});

  H5Dataset empty = good;
  empty.dims = {2, 0, 2};
  empty.values.clear();
  write_h5(path("empty.h5"), {empty});
  expect_error([&] { load_density_hdf5(path("empty.h5")); }, {"empty.h5", "tau_v", "zero size"});
}

TEST_F(DensityFiles, EverySourceRefusesNanInfAndNegativeValues) {
  struct Bad {
    double value;
    const char* text;
  };
  for (const Bad bad : {Bad{std::nan(""), "nan"}, Bad{-0.5, "-0.5"},
                        Bad{std::numeric_limits<double>::infinity(), "inf"}}) {
    H5Dataset set;
    set.dims = {2, 3, 4};  // nz, ny, nx
    set.values.assign(24, 0.5);
    set.values[4 * 3 * 1 + 4 * 2 + 1] = bad.value;  // x=1, y=2, z=1: index 21
    set.voxel_size = 0.1;
    write_h5(path("bad.h5"), {set});
    expect_error([&] { load_density_hdf5(path("bad.h5")); },
                 {"bad.h5", "'tau_v'", "x=1, y=2, z=1", "index 21", bad.text});

    write_fits(path("bad.fits"), {4, 3, 2}, set.values, FLOAT_IMG, {{{"CDELT1", 0.1}, {"CDELT2", 0.1}, {"CDELT3", 0.1}}, {}, {}});
    // cfitsio reads NaN and Inf as undefined pixels.
    expect_error([&] { load_density_fits(path("bad.fits")); },
                 {"bad.fits", "x=1, y=2, z=1", "index 21", bad.value < 0 ? bad.text : "undefined"});
  }
}

TEST_F(DensityFiles, TooLargeGridsAreRefusedBeforeReading) {
  // Declared but never written: HDF5 allocates no space for it.
  H5Dataset huge;
  huge.dims = {100000, 100000, 100000};
  huge.voxel_size = 0.1;
  write_h5(path("huge.h5"), {huge});
  EXPECT_LT(testing::fs::file_size(path("huge.h5")), 100000u);
  expect_error([&] { load_density_hdf5(path("huge.h5")); },
               {"huge.h5", "'tau_v'", "100000 x 100000 x 100000", "3.55 PiB", "limit", "half the physical memory"});

  expect_error([] { check_grid_size("thing", 10, 10, 10, 4, 3000); }, {"thing", "3.91 KiB", "limit of 2.93 KiB"});
  EXPECT_NO_THROW(check_grid_size("thing", 10, 10, 10, 4, 4000));
  expect_error([] { check_grid_size("thing", 10, 0, 10); }, {"thing", "zero size"});
  EXPECT_GT(grid_memory_limit_bytes(), size_t(1) << 26);
}

// ------------------------------------------------------------ FITS

FitsKeys cdelt(double v) { return {{{"CDELT1", v}, {"CDELT2", v}, {"CDELT3", v}}, {}, {}}; }

TEST_F(DensityFiles, FitsRoundTripKeepsAxisOrderValuesAndVoxel) {
  const int nx = 5, ny = 4, nz = 3;
  const std::vector<double> values = distinct_values(nx, ny, nz);
  for (int bitpix : {FLOAT_IMG, DOUBLE_IMG}) {
    write_fits(path("cube.fits"), {nx, ny, nz}, values, bitpix, cdelt(0.05));
    const DensityGrid g = load_density_fits(path("cube.fits"));
    EXPECT_EQ(g.shape.nx, nx);
    EXPECT_EQ(g.shape.ny, ny);
    EXPECT_EQ(g.shape.nz, nz);
    EXPECT_FLOAT_EQ(g.shape.voxel, 0.05f);
    for (size_t i = 0; i < values.size(); ++i) EXPECT_EQ(g.tau_v[i], float(values[i]));
    // NAXIS1 is x: voxel (x=3, y=1, z=2) holds 200 + 10 + 3.
    EXPECT_EQ(g.tau_v[g.shape.index(3, 1, 2)], 213.25f);
  }
}

TEST_F(DensityFiles, FitsIntegerImagesAreScaled) {
  FitsKeys keys = cdelt(0.1);
  keys.numbers["BSCALE"] = 0.5;
  keys.numbers["BZERO"] = 2.0;
  write_fits(path("int.fits"), {2, 2, 2}, {0, 1, 2, 3, 4, 5, 6, 7}, SHORT_IMG, keys);
  const DensityGrid g = load_density_fits(path("int.fits"));
  for (int i = 0; i < 8; ++i) EXPECT_EQ(g.tau_v[size_t(i)], 0.5f * float(i) + 2.0f);

  // An undefined (BLANK) pixel is refused.
  FitsKeys blank = cdelt(0.1);
  blank.integers["BLANK"] = -1;
  write_fits(path("blank.fits"), {2, 2, 2}, {0, 1, 2, -1, 4, 5, 6, 7}, SHORT_IMG, blank);
  expect_error([&] { load_density_fits(path("blank.fits")); }, {"blank.fits", "index 3", "undefined"});
}

TEST_F(DensityFiles, FitsVoxelSizeFromTheSceneAndOriginFromWcs) {
  write_fits(path("nocdelt.fits"), {2, 3, 4}, std::vector<double>(24, 1.0), FLOAT_IMG, {});
  expect_error([&] { load_density_fits(path("nocdelt.fits")); }, {"nocdelt.fits", "CDELT", "voxel_size_pc"});
  EXPECT_FLOAT_EQ(load_density_fits(path("nocdelt.fits"), 0.3).shape.voxel, 0.3f);

  write_fits(path("cdelt.fits"), {2, 3, 4}, std::vector<double>(24, 1.0), FLOAT_IMG, cdelt(0.2));
  EXPECT_FLOAT_EQ(load_density_fits(path("cdelt.fits"), 0.2).shape.voxel, 0.2f);
  expect_error([&] { load_density_fits(path("cdelt.fits"), 0.3); }, {"cdelt.fits", "0.3", "CDELT1 = 0.2"});

  FitsKeys wcs = cdelt(0.5);
  for (int a = 1; a <= 3; ++a) {
    wcs.numbers["CRPIX" + std::to_string(a)] = 1.0;
    wcs.numbers["CRVAL" + std::to_string(a)] = 10.0 * a;
  }
  write_fits(path("wcs.fits"), {2, 3, 4}, std::vector<double>(24, 1.0), FLOAT_IMG, wcs);
  const DensityGrid g = load_density_fits(path("wcs.fits"));
  // The centre of pixel 1 is at CRVAL, so the minimum corner is half a voxel before it.
  EXPECT_FLOAT_EQ(g.shape.origin.x, 9.75f);
  EXPECT_FLOAT_EQ(g.shape.origin.y, 19.75f);
  EXPECT_FLOAT_EQ(g.shape.origin.z, 29.75f);
}

TEST_F(DensityFiles, FitsRefusesBadHeaders) {
  const std::vector<double> ones(24, 1.0);
  FitsKeys uneven = cdelt(0.2);
  uneven.numbers["CDELT3"] = 0.4;
  write_fits(path("uneven.fits"), {2, 3, 4}, ones, FLOAT_IMG, uneven);
  expect_error([&] { load_density_fits(path("uneven.fits")); }, {"uneven.fits", "CDELT3", "cubes"});

  write_fits(path("neg.fits"), {2, 3, 4}, ones, FLOAT_IMG, cdelt(-0.2));
  expect_error([&] { load_density_fits(path("neg.fits")); }, {"neg.fits", "CDELT1", "flipped", "positive"});
  // One flipped axis is named as such, not taken for a voxel that is no cube.
  FitsKeys flipped_x = cdelt(0.2);
  flipped_x.numbers["CDELT1"] = -0.2;
  write_fits(path("flipped.fits"), {2, 3, 4}, ones, FLOAT_IMG, flipped_x);
  expect_error([&] { load_density_fits(path("flipped.fits")); }, {"flipped.fits", "CDELT1 = -0.2", "x axis is flipped"});
  FitsKeys flipped_z = cdelt(0.2);
  flipped_z.numbers["CDELT3"] = -0.2;
  write_fits(path("flipped_z.fits"), {2, 3, 4}, ones, FLOAT_IMG, flipped_z);
  expect_error([&] { load_density_fits(path("flipped_z.fits")); }, {"CDELT3 = -0.2", "z axis is flipped"});

  FitsKeys degrees = cdelt(0.2);
  degrees.strings["CUNIT2"] = "deg";
  write_fits(path("deg.fits"), {2, 3, 4}, ones, FLOAT_IMG, degrees);
  expect_error([&] { load_density_fits(path("deg.fits")); }, {"deg.fits", "CUNIT2", "deg"});
  FitsKeys parsecs = cdelt(0.2);
  parsecs.strings["CUNIT1"] = "pc";
  write_fits(path("pc.fits"), {2, 3, 4}, ones, FLOAT_IMG, parsecs);
  EXPECT_NO_THROW(load_density_fits(path("pc.fits")));

  write_fits(path("image.fits"), {4, 6}, ones, FLOAT_IMG, cdelt(0.2));
  expect_error([&] { load_density_fits(path("image.fits")); }, {"image.fits", "NAXIS = 3", "NAXIS = 2"});

  write_text("junk.fits", std::string(2880, 'x'));
  expect_error([&] { load_density_fits(path("junk.fits")); }, {"junk.fits", "FITS"});
  expect_error([&] { load_density_fits(path("absent.fits")); }, {"absent.fits", "cannot open"});
}

// ------------------------------------------------------------ emission

TEST_F(DensityFiles, EmissionMustMatchTheDensityShape) {
  GridShape shape;
  shape.nx = 4;
  shape.ny = 3;
  shape.nz = 2;
  shape.voxel = 0.1f;
  H5Dataset e;
  e.name = "emission_B";
  e.dims = {2, 3, 4};
  e.values = distinct_values(4, 3, 2);
  H5Dataset wrong = e;
  wrong.name = "emission_V";
  wrong.dims = {3, 3, 4};
  wrong.values = distinct_values(4, 3, 3);
  H5Dataset voxel = e;
  voxel.name = "emission_R";
  voxel.voxel_size = 0.2;
  write_h5(path("em.h5"), {e, wrong, voxel});
  const std::vector<float> b = load_emission_hdf5(path("em.h5"), "emission_B", shape);
  EXPECT_EQ(b[shape.index(3, 2, 1)], 123.25f);
  expect_error([&] { load_emission_hdf5(path("em.h5"), "emission_V", shape); },
               {"em.h5", "emission_V", "4 x 3 x 3", "differs"});
  expect_error([&] { load_emission_hdf5(path("em.h5"), "emission_R", shape); },
               {"em.h5", "emission_R", "voxel_size 0.2"});
}

// ------------------------------------------------------------ procedural

ProceduralParams small_params() {
  ProceduralParams p;
  p.n = 48;
  return p;
}

TEST(Procedural, SameSeedSameGridOtherSeedOtherGrid) {
  const ProceduralParams p = small_params();
  const DensityGrid a = procedural_nebula(p);
  const DensityGrid b = procedural_nebula(p);
  EXPECT_EQ(a.tau_v, b.tau_v);  // bit for bit
  ProceduralParams q = p;
  q.seed = 2;
  const DensityGrid c = procedural_nebula(q);
  size_t differ = 0;
  for (size_t i = 0; i < a.tau_v.size(); ++i) differ += a.tau_v[i] != c.tau_v[i];
  EXPECT_GT(differ, a.tau_v.size() * 9 / 10);
  // A seed above 2^32 reaches the key's high word.
  q.seed = p.seed + (uint64_t(1) << 32);
  EXPECT_NE(procedural_nebula(q).tau_v, a.tau_v);
}

TEST(Procedural, ShapeUnitsAndValues) {
  ProceduralParams p = small_params();
  p.size_pc = 3.0;
  p.origin_pc = Vec3{-1.5f, 0.0f, 2.0f};
  const DensityGrid g = procedural_nebula(p);
  EXPECT_EQ(g.shape.nx, 48);
  EXPECT_EQ(g.shape.ny, 48);
  EXPECT_EQ(g.shape.nz, 48);
  EXPECT_FLOAT_EQ(g.shape.voxel, 3.0f / 48);
  EXPECT_EQ(g.shape.origin.x, -1.5f);
  for (float v : g.tau_v) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0.0f);
  }
  const Vec3 star = procedural_star_position(p);
  EXPECT_FLOAT_EQ(star.x, 0.0f);
  EXPECT_FLOAT_EQ(star.y, 1.5f);
  EXPECT_FLOAT_EQ(star.z, 3.5f);
}

// Mean tau_v over voxels whose centre (fractions of the edge) passes `keep`.
template <class Keep>
double mean_where(const DensityGrid& g, Keep keep) {
  double sum = 0;
  size_t count = 0;
  const int n = g.shape.nx;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double u = (x + 0.5) / n, v = (y + 0.5) / n, w = (z + 0.5) / n;
        if (!keep(u, v, w)) continue;
        sum += g.tau_v[g.shape.index(x, y, z)];
        ++count;
      }
  EXPECT_GT(count, 0u);
  return sum / double(count);
}

TEST(Procedural, BubbleIsEmptierThanShellAndFarSideDenserThanNearSide) {
  const ProceduralParams p;  // the defaults, at n = 128
  const DensityGrid g = procedural_nebula(p);
  const double l = std::sqrt(1.25);  // |wind_direction| = |(0, -1, 0.5)|
  const double cx = 0.5, cy = 0.5 - p.bubble_offset / l, cz = 0.5 + 0.5 * p.bubble_offset / l;
  auto dist = [&](double u, double v, double w) {
    return std::sqrt((u - cx) * (u - cx) + (v - cy) * (v - cy) + (w - cz) * (w - cz));
  };
  // Within 0.05 edge of the star versus the shell's peak ring (+-0.015 of its centre).
  const double bubble = mean_where(g, [](double u, double v, double w) {
    return (u - 0.5) * (u - 0.5) + (v - 0.5) * (v - 0.5) + (w - 0.5) * (w - 0.5) < 0.05 * 0.05;
  });
  const double shell_radius = p.bubble_radius + 0.5 * p.shell_thickness;
  const double shell = mean_where(g, [&](double u, double v, double w) {
    return std::fabs(dist(u, v, w) - shell_radius) < 0.015;
  });
  // Far (y > star + 0.1) versus near (y < star - 0.1) half-spaces.
  const double far = mean_where(g, [](double, double v, double) { return v > 0.6; });
  const double near = mean_where(g, [](double, double v, double) { return v < 0.4; });
  // Optical depth from the star to the cube's faces along -y (towards the
  // camera side) and +y (the far side).
  double to_near = 0, to_far = 0;
  for (int y = 0; y < p.n; ++y) (y < p.n / 2 ? to_near : to_far) += g.tau_v[g.shape.index(p.n / 2, y, p.n / 2)];
  std::printf("default nebula, n = 128: mean tau_v per voxel within 0.05 edge of the star %.4f, "
              "in the shell's peak ring %.4f (ratio %.3f); far half-space (y > 0.6) %.4f, near "
              "(y < 0.4) %.4f (ratio %.2f); tau_v from the star to the near face %.2f, to the far "
              "face %.2f\n",
              bubble, shell, bubble / shell, far, near, far / near, to_near, to_far);
  EXPECT_LT(bubble, 0.05 * shell);
  EXPECT_GT(far, 2.0 * near);
  EXPECT_GT(to_far, 3.0 * to_near);
}

TEST(Procedural, ZeroNoiseAmplitudeGivesTheSmoothProfile) {
  ProceduralParams p = small_params();
  p.noise_amplitude = 0;
  const DensityGrid a = procedural_nebula(p);
  p.seed = 99;
  EXPECT_EQ(procedural_nebula(p).tau_v, a.tau_v);  // the seed no longer matters

  // Without noise and wind offset, the near half-space is symmetric about
  // the star in x: voxels mirrored in x hold equal values.
  p.bubble_offset = 0;
  const DensityGrid s = procedural_nebula(p);
  const int n = p.n;
  for (int z = 0; z < n; z += 5)
    for (int y = 0; y < n; y += 3)
      for (int x = 0; x < n / 2; ++x)
        ASSERT_EQ(s.tau_v[s.shape.index(x, y, z)], s.tau_v[s.shape.index(n - 1 - x, y, z)]);

  // Far from the far side (y < 0.35), values follow the documented formula.
  const double shell_k = 4 * std::log(2.0) / (p.shell_thickness * p.shell_thickness);
  for (int z = 0; z < n; z += 7)
    for (int y = 0; y < n * 35 / 100; y += 2)
      for (int x = 0; x < n; x += 3) {
        const double u = (x + 0.5) / n, v = (y + 0.5) / n, w = (z + 0.5) / n;
        const double d = std::sqrt((u - 0.5) * (u - 0.5) + (v - 0.5) * (v - 0.5) + (w - 0.5) * (w - 0.5));
        const double base = d < p.bubble_radius
                                ? p.bubble_tau
                                : p.cloud_tau * std::exp(-(d - p.bubble_radius) / p.scale_length);
        const double s2 = d - p.bubble_radius - 0.5 * p.shell_thickness;
        const double expected = (base + p.shell_tau * std::exp(-shell_k * s2 * s2)) / n;
        ASSERT_NEAR(s.tau_v[s.shape.index(x, y, z)], expected, 1e-6 * expected + 1e-12);
      }
}

TEST(Procedural, NoiseIsTheDocumentedFractalValueNoise) {
  ProceduralParams p = small_params();
  ProceduralParams flat = p;
  flat.noise_amplitude = 0;
  const DensityGrid noisy = procedural_nebula(p), smooth = procedural_nebula(flat);
  const int n = p.n;
  double lo = 1, hi = -1;
  for (int z = 1; z < n; z += 5)
    for (int y = 2; y < n; y += 5)
      for (int x = 3; x < n; x += 5) {
        const size_t i = noisy.shape.index(x, y, z);
        const double noise = procedural_noise(p, (x + 0.5) / n, (y + 0.5) / n, (z + 0.5) / n);
        lo = std::min(lo, noise);
        hi = std::max(hi, noise);
        ASSERT_NEAR(noisy.tau_v[i] / smooth.tau_v[i], std::exp(p.noise_amplitude * noise), 2e-6 * std::exp(p.noise_amplitude * noise));
      }
  EXPECT_GE(lo, -1.0);
  EXPECT_LE(hi, 1.0);
  EXPECT_LT(lo, -0.2);  // the field varies
  EXPECT_GT(hi, 0.2);
  // Octaves above n / 2 cycles per edge are left out: at n = 4 only none remain.
  ProceduralParams coarse = p;
  coarse.n = 4;
  coarse.noise_frequency = 3;
  EXPECT_EQ(procedural_noise(coarse, 0.3, 0.6, 0.2), 0.0);
}

TEST(Procedural, RefusesBadParameters) {
  auto refused = [](auto edit, const std::vector<std::string>& pieces) {
    ProceduralParams p;
    edit(p);
    expect_error([&] { validate_procedural(p); }, pieces);
    expect_error([&] { procedural_nebula(p); }, pieces);
  };
  refused([](ProceduralParams& p) { p.n = 1; }, {"n:", "at least 2"});
  refused([](ProceduralParams& p) { p.n = 100000; }, {"n:", "limit"});
  refused([](ProceduralParams& p) { p.bubble_offset = 0.3; }, {"bubble_offset", "bubble_radius"});
  refused([](ProceduralParams& p) { p.star = Vec3{0.5f, 1.2f, 0.5f}; }, {"star", "[0, 1]"});
  refused([](ProceduralParams& p) { p.wind_direction = Vec3{0, 0, 0}; }, {"wind_direction", "non-zero"});
  refused([](ProceduralParams& p) { p.shell_tau = -1; }, {"shell_tau", "-1"});
  refused([](ProceduralParams& p) { p.size_pc = std::nan(""); }, {"size_pc", "nan"});
  refused([](ProceduralParams& p) { p.noise_octaves = 17; }, {"noise_octaves"});
  refused([](ProceduralParams& p) { p.noise_lacunarity = 1; }, {"noise_lacunarity"});
  EXPECT_FALSE(check_procedural(ProceduralParams{}).has_value());
}

// The peak resident memory of this process so far (bytes).
size_t peak_resident_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return size_t(usage.ru_maxrss) * 1024;
}

// Issue 17, item 4: a small file claiming a 4 GiB grid is refused by the
// cheap checks (no voxel_size; never written) before the values are
// allocated: it allocated and zeroed the 4 GiB first.
TEST_F(DensityFiles, CheapChecksComeBeforeTheAllocation) {
  H5Dataset claim;
  claim.dims = {1024, 1024, 1024};
  write_h5(path("claim.h5"), {claim});
  EXPECT_LT(testing::fs::file_size(path("claim.h5")), 100000u);
  const size_t before = peak_resident_bytes();
  expect_error([&] { load_density_hdf5(path("claim.h5")); }, {"claim.h5", "missing attribute 'voxel_size'"});
  claim.voxel_size = 0.1;
  write_h5(path("unwritten.h5"), {claim});
  expect_error([&] { load_density_hdf5(path("unwritten.h5")); }, {"unwritten.h5", "never written"});
  EXPECT_LT(peak_resident_bytes() - before, size_t(256) << 20) << "the loader allocated the claimed grid";
}

// Issue 17, item 4: a file cut short is refused before the allocation, naming
// the file.
TEST_F(DensityFiles, TruncatedFileIsRefused) {
  H5Dataset set;
  set.dims = {16, 16, 16};
  set.values.assign(16 * 16 * 16, 0.5);
  set.voxel_size = 0.1;
  write_h5(path("cut.h5"), {set});
  const auto size = testing::fs::file_size(path("cut.h5"));
  testing::fs::resize_file(path("cut.h5"), size - 4000);
  expect_error([&] { load_density_hdf5(path("cut.h5")); }, {"cut.h5"});
}

// Issue 17, a fuzz finding (scripts/fuzz.sh): a 2 KB density file whose
// damaged metadata makes libhdf5 ask malloc for 2^51 bytes in H5C_protect.
// Whatever libhdf5 does with it, the loader ends in one line naming the file.
TEST_F(DensityFiles, FuzzFindingHugeMetadataAllocation) {
  const std::string file = std::string(NEBULA_SCENES_DIR) + "/../fuzz/findings/density_hdf5_huge_metadata_alloc.h5";
  expect_error([&] { load_density_hdf5(file); }, {"density_hdf5_huge_metadata_alloc.h5"});
}

}  // namespace
}  // namespace nebula
