#include "diffuse/diffuse_bake.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/math.h"
#include "diffuse/test_quadrature.h"
#include "montecarlo/henyey_greenstein.h"

namespace nebula {
namespace {

// A cube of n^3 voxels over [-1, 1]^3 of uniform tau_v.
DensityGrid cube(int n, float tau_v) {
  DensityGrid g;
  g.shape.nx = g.shape.ny = g.shape.nz = n;
  g.shape.voxel = 2.0f / n;
  g.shape.origin = {-1, -1, -1};
  g.tau_v.assign(g.shape.count(), tau_v);
  return g;
}

// The optically thin table of one band (the response needs one).
ScatteringTable thin_table(double g) {
  ScatteringTable t = ScatteringTable::make_axes(2.0, 5, AngularBinning::UniformTheta, 72);
  t.g = g;
  for (int i = 0; i < t.n_tau(); ++i)
    for (int k = 0; k < t.n_mu(); ++k)
      t.P[t.index(i, k)] = static_cast<float>(t.tau[i] * hg_bin_mean(g, t.mu_edges[k], t.mu_edges[k + 1]));
  return t;
}

// Band V of the given dust, answering through `table`.
DiffuseBand v_band(float albedo, float g, const ScatteringTable& table) {
  DiffuseBand band;
  band.name = "V";
  band.albedo = albedo;
  band.g = g;
  band.table = &table;
  return band;
}

// Entry and exit distances of the ray s + t d (unit d) through the box [lo, hi]; false when it misses.
bool box_interval(const double s[3], const double d[3], const double lo[3], const double hi[3], double& t0, double& t1) {
  t0 = -1e300;
  t1 = 1e300;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (s[k] < lo[k] || s[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - s[k]) / d[k], b = (hi[k] - s[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 < t1;
}

// The fluence at x of light scattered once by a uniform cube [-1, 1]^3 of
// extinction sigma and albedo a, isotropically, lit by a star of power phi at
// `star`, leaving out the light scattered inside the voxel box [lo, hi] around
// x (what the bake leaves to that voxel's table):
//   a sigma phi / (16 pi^2) integral dV' exp(-sigma (r' + rho)) / (r'^2 rho^2),
// in coordinates about the star (r'^2 cancels); along each direction the part
// inside the excluded box is cut out of the r' integral, so the integrand stays
// bounded (rho >= l / 2).
double single_scattering_fluence(const double x[3], const double star[3], const double lo[3], const double hi[3],
                                 double sigma, double albedo, double phi) {
  std::vector<double> mu, wmu, r, wr;
  testing::gauss_legendre(160, -1, 1, mu, wmu);
  const int n_phi = 320;
  const double cube_lo[3] = {-1, -1, -1}, cube_hi[3] = {1, 1, 1};
  double sum = 0;
  for (size_t i = 0; i < mu.size(); ++i)
    for (int j = 0; j < n_phi; ++j) {
      const double ph = 2 * kPiD * (j + 0.5) / n_phi, st = std::sqrt(1 - mu[i] * mu[i]);
      const double d[3] = {st * std::cos(ph), st * std::sin(ph), mu[i]};
      double t0, t1;
      box_interval(star, d, cube_lo, cube_hi, t0, t1);
      const double end = t1;  // the star is inside the cube
      double a0, a1;
      std::vector<std::pair<double, double>> pieces;
      if (box_interval(star, d, lo, hi, a0, a1) && a1 > 0) {
        a0 = std::max(a0, 0.0);
        if (a0 > 0) pieces.push_back({0.0, a0});
        if (a1 < end) pieces.push_back({a1, end});
      } else {
        pieces.push_back({0.0, end});
      }
      double line = 0;
      for (auto [p, q] : pieces) {
        testing::gauss_legendre(16, p, q, r, wr);
        for (size_t k = 0; k < r.size(); ++k) {
          const double xp[3] = {star[0] + r[k] * d[0], star[1] + r[k] * d[1], star[2] + r[k] * d[2]};
          const double rho2 = (xp[0] - x[0]) * (xp[0] - x[0]) + (xp[1] - x[1]) * (xp[1] - x[1]) +
                              (xp[2] - x[2]) * (xp[2] - x[2]);
          line += wr[k] * std::exp(-sigma * (r[k] + std::sqrt(rho2))) / rho2;
        }
      }
      sum += wmu[i] * (2 * kPiD / n_phi) * line;
    }
  return albedo * sigma * phi / (16 * kPiD * kPiD) * sum;
}

// The track-length estimator against the integral it estimates: the field's
// l = 0 part of light scattered once, in a thin uniform cube, against a
// quadrature of the single-scattering integral. The tolerance is 4 standard
// errors of the mean of independent bakes (seeds), plus the quadrature's own
// error (under 0.3%: it moves by less when its resolution is halved).
TEST(DiffuseBake, FirstScatteredFieldIsTheSingleScatteringIntegral) {
  const int n = 16;
  const float tau_v = 0.005f;  // per voxel: the cube is 0.08 across, attenuation inside a voxel is negligible
  const DensityGrid grid = cube(n, tau_v);
  const ScatteringTable table = thin_table(0.0);
  DiffuseBand band;
  band.name = "V";
  band.extinction_ratio = 1;
  band.albedo = 0.5f;
  band.g = 0.0f;
  band.table = &table;
  const Vec3 star{0.01f, 0.02f, 0.03f};
  const std::vector<StarLight> stars{{star, {100.0f}}};
  DiffuseBakeOptions o;
  o.degree = 0;
  o.cells = n;
  o.photons = 1u << 18;
  o.max_orders = 1;
  const int runs = 8;
  const int cells[3][3] = {{12, 8, 8}, {8, 3, 9}, {4, 12, 13}};  // 4 to 6 voxels from the star
  std::vector<std::vector<double>> estimate(3);
  for (int run = 0; run < runs; ++run) {
    o.seed = 101 + run;
    const DiffuseField f = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
    ASSERT_EQ(f.shift, 0);
    for (int c = 0; c < 3; ++c)
      estimate[c].push_back(f.band_coeffs(0)[f.cells.index(cells[c][0], cells[c][1], cells[c][2])] * std::sqrt(4 * kPiD));
  }
  const double sigma = tau_v / grid.shape.voxel, l = grid.shape.voxel;
  const double s[3] = {star.x, star.y, star.z};
  for (int c = 0; c < 3; ++c) {
    double mean = 0, var = 0;
    for (double e : estimate[c]) mean += e / runs;
    for (double e : estimate[c]) var += (e - mean) * (e - mean) / (runs - 1);
    const double se = std::sqrt(var / runs);
    // The bake averages over the voxel; the quadrature takes its 2^3 Gauss points.
    const double lo[3] = {-1 + cells[c][0] * l, -1 + cells[c][1] * l, -1 + cells[c][2] * l};
    const double hi[3] = {lo[0] + l, lo[1] + l, lo[2] + l};
    double expected = 0;
    const double g = 0.5 / std::sqrt(3.0);
    for (int k = 0; k < 8; ++k) {
      const double x[3] = {lo[0] + l * (0.5 + ((k & 1) ? g : -g)), lo[1] + l * (0.5 + ((k & 2) ? g : -g)),
                           lo[2] + l * (0.5 + ((k & 4) ? g : -g))};
      expected += single_scattering_fluence(x, s, lo, hi, sigma, 0.5, 100.0) / 8;
    }
    std::printf("cell (%d, %d, %d): bake %.5g +- %.2g, single-scattering integral %.5g (%+.2f%%)\n", cells[c][0],
                cells[c][1], cells[c][2], mean, se, expected, 100 * (mean / expected - 1));
    EXPECT_LT(se, 0.02 * expected) << "too few photons for the test to mean anything";
    EXPECT_NEAR(mean, expected, 4 * se + 0.003 * expected) << "cell " << c;
  }
}

// Sums of fixed-point integers do not depend on the order they come in.
TEST(DiffuseBake, TheSameFieldOnOneThreadOrMany) {
  const DensityGrid grid = cube(8, 0.3f);
  const ScatteringTable table = thin_table(0.6);
  const DiffuseBand band = v_band(0.8f, 0.6f, table);
  DiffuseBakeOptions o;
  o.photons = 20000;
  const std::vector<StarLight> stars{{{0.1f, -0.2f, 0.3f}, {1.0f}}};
  const DiffuseField many = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
  DiffuseField one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
  }
  ASSERT_EQ(many.host_packed().size(), one.host_packed().size());
  for (size_t i = 0; i < one.host_packed().size(); ++i) ASSERT_EQ(many.host_packed()[i], one.host_packed()[i]) << i;
  // Sums of each thread's own, or one set added to atomically: the same field.
  o.private_sums_bytes = 0;
  const DiffuseField atomic = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
  EXPECT_EQ(atomic.host_packed(), many.host_packed());
}

// Common streams (the spectral renderer's nodes): two bands alike but for
// their names take the same photons, so their fields are equal bit for bit;
// each on its own streams (the default) they are two draws of the same field.
TEST(DiffuseBake, CommonStreamsGiveBandsAlikeOneField) {
  const DensityGrid grid = cube(8, 0.3f);
  const ScatteringTable table = thin_table(0.6);
  DiffuseBand a = v_band(0.8f, 0.6f, table), b = a;
  b.name = "W";
  DiffuseBakeOptions o;
  o.photons = 20000;
  const std::vector<StarLight> stars{{{0.1f, -0.2f, 0.3f}, {1.0f, 1.0f}}};
  const auto bands_equal = [](const DiffuseField& f) {
    const std::vector<float>& p = f.host_packed();  // [(cell * coeffs + k) * 4 + band]
    bool equal = true;
    for (size_t i = 0; i + 1 < p.size(); i += 4) equal = equal && p[i] == p[i + 1];
    return equal;
  };
  EXPECT_FALSE(bands_equal(bake_diffuse(grid, {a, b}, stars, o, Backend::Cpu)));
  o.common_streams = true;
  EXPECT_TRUE(bands_equal(bake_diffuse(grid, {a, b}, stars, o, Backend::Cpu)));
}

// Zonal degrees add to the harmonics without changing them (the same photons,
// the same sums), and they are what they say: the degrees beyond the
// harmonics of the light about the direction from the star. Around a star in
// a uniform cube the field is nearly symmetric about that direction, so a
// cell's zonal degree l equals a degree-4 bake's harmonics of degree l seen
// along it, sum_m L_lm Y_lm(r), over Y_l0 on the axis.
TEST(DiffuseBakeZonal, AddToTheHarmonicsAndAreTheirDegreesAlongTheStarsDirection) {
  const DensityGrid grid = cube(16, 0.08f);
  const ScatteringTable table = thin_table(0.9);
  const DiffuseBand band = v_band(0.8f, 0.9f, table);
  const Vec3 star{0.0f, 0.0f, 0.0f};
  const std::vector<StarLight> stars{{star, {1.0f}}};
  DiffuseBakeOptions o;
  o.photons = 400000;
  o.cells = 16;
  o.degree = 1;
  const DiffuseField plain = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
  o.zonal = 4;
  const DiffuseField zonal = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
  o.zonal = 0;
  o.degree = 4;
  const DiffuseField full = bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
  ASSERT_EQ(zonal.n_coeffs(), 4 + 3);
  ASSERT_EQ(zonal.zonal_stars, 1);
  const std::vector<float> p = plain.band_coeffs(0), z = zonal.band_coeffs(0), f = full.band_coeffs(0);
  const GridShape& cells = zonal.cells;
  double got[5] = {}, want[5] = {};
  for (int cz = 0; cz < cells.nz; ++cz)
    for (int cy = 0; cy < cells.ny; ++cy)
      for (int cx = 0; cx < cells.nx; ++cx) {
        const size_t cell = cells.index(cx, cy, cz);
        for (int k = 0; k < 4; ++k) ASSERT_EQ(z[cell * 7 + k], p[cell * 4 + k]) << "cell " << cell << " k " << k;
        const Vec3 r = cells.centre(cx, cy, cz) - star;
        if (length(r) < 0.5f) continue;  // near the star the light is far from symmetric within a cell
        float y[kMaxShCoeffs], axis[kMaxShDegree + 1];
        sh_basis(4, normalize(r), y);
        zonal_basis(0, 4, 1.0f, axis);
        for (int l = 2; l <= 4; ++l) {
          double along = 0;
          for (int m = -l; m <= l; ++m) along += f[cell * 25 + size_t(l * l + l + m)] * y[l * l + l + m];
          want[l] += along / axis[l];
          got[l] += z[cell * 7 + 4 + size_t(l - 2)];
        }
      }
  for (int l = 2; l <= 4; ++l) {
    std::printf("degree %d: zonal sum %.5g, the harmonics along the star's direction %.5g (%+.1f%%)\n", l, got[l],
                want[l], 100 * (got[l] / want[l] - 1));
    EXPECT_GT(want[l], 0.0) << "forward light: positive along the direction from the star";
    // The zonal deposits take the direction at each chord's middle, the
    // harmonics' check the cell's centre: a few percent apart at l = 4.
    EXPECT_NEAR(got[l] / want[l], 1.0, 0.06) << "l " << l;
  }
}

// The field's noise estimate (its two halves) falls as 1 / sqrt(photons).
TEST(DiffuseBake, NoiseFallsAsOneOverTheRootOfThePhotons) {
  const DensityGrid grid = cube(8, 0.2f);
  const ScatteringTable table = thin_table(0.6);
  const DiffuseBand band = v_band(0.6f, 0.6f, table);
  DiffuseBakeOptions o;
  const std::vector<StarLight> stars{{{0.0f, 0.0f, 0.0f}, {1.0f}}};
  DiffuseBakeStats few, more;
  o.photons = 20000;
  bake_diffuse(grid, {band}, stars, o, Backend::Cpu, &few);
  o.photons = 320000;
  bake_diffuse(grid, {band}, stars, o, Backend::Cpu, &more);
  std::printf("noise %.4f at 2e4 photons, %.4f at 3.2e5 (ratio %.2f, expected 4)\n", few.noise[0], more.noise[0],
              few.noise[0] / more.noise[0]);
  EXPECT_NEAR(few.noise[0] / more.noise[0], 4.0, 1.0);
}

TEST(DiffuseBake, RefusesBadOptionsNamingThem) {
  const DensityGrid grid = cube(4, 0.1f);
  const ScatteringTable table = thin_table(0.6);
  DiffuseBand band;
  band.name = "V";
  band.table = &table;
  const std::vector<StarLight> stars{{{0, 0, 0}, {1.0f}}};
  auto parameter = [&](DiffuseBakeOptions o) {
    try {
      bake_diffuse(grid, {band}, stars, o, Backend::Cpu);
    } catch (const ParameterError& e) {
      return e.parameter();
    }
    return std::string("accepted");
  };
  DiffuseBakeOptions o;
  o.photons = 1000;
  EXPECT_EQ(parameter(o), "accepted");
  o.degree = kMaxDiffuseDegree + 1;
  EXPECT_EQ(parameter(o), "diffuse_order");
  o = {};
  o.cells = 0;
  EXPECT_EQ(parameter(o), "diffuse_cells");
  o = {};
  o.photons = 0;
  EXPECT_EQ(parameter(o), "diffuse_photons");
  o = {};
  o.shared_order_buckets = kMaxOrderBuckets + 1;
  EXPECT_EQ(parameter(o), "shared_order_buckets");
  o.shared_order_buckets = -2;
  EXPECT_EQ(parameter(o), "shared_order_buckets");
  band.table = nullptr;
  EXPECT_THROW(bake_diffuse(grid, {band}, stars, DiffuseBakeOptions{}, Backend::Cpu), Error);
}

// A sweep's albedos from one pass (bake_diffuse_shared): bands that differ only
// in their albedo, each band traced at its largest.
struct SharedCase {
  DensityGrid grid = cube(12, 0.25f);
  ScatteringTable table = thin_table(0.6);
  std::vector<StarLight> stars{{{0.1f, -0.05f, 0.2f}, {3.0f, 2.0f}}};
  std::vector<DiffuseBand> bands(float albedo_b, float albedo_v) const {
    std::vector<DiffuseBand> b(2);
    b[0].name = "B";
    b[0].extinction_ratio = 1.2f;
    b[0].albedo = albedo_b;
    b[1].name = "V";
    b[1].albedo = albedo_v;
    for (DiffuseBand& band : b) {
      band.g = 0.6f;
      band.table = &table;
    }
    return b;
  }
};

// The set at the largest albedo is traced exactly as a bake of its own.
TEST(DiffuseBakeShared, TheLargestAlbedoGetsItsOwnFieldBitForBit) {
  const SharedCase c;
  DiffuseBakeOptions o;
  o.photons = 20000;
  o.cells = 6;
  std::vector<DiffuseBakeStats> stats;
  const std::vector<DiffuseField> shared = bake_diffuse_shared(
      c.grid, {c.bands(0.3f, 0.5f), c.bands(0.9f, 0.8f), c.bands(0.6f, 0.2f)}, c.stars, o, Backend::Cpu, &stats);
  ASSERT_EQ(shared.size(), 3u);
  ASSERT_EQ(stats.size(), 3u);
  DiffuseBakeStats alone_stats;
  const DiffuseField alone = bake_diffuse(c.grid, c.bands(0.9f, 0.8f), c.stars, o, Backend::Cpu, &alone_stats);
  for (size_t b = 0; b < 2; ++b) {
    EXPECT_EQ(shared[1].band_coeffs(b), alone.band_coeffs(b)) << "band " << b;
    EXPECT_EQ(stats[1].noise[b], alone_stats.noise[b]);
    EXPECT_EQ(shared[1].response[b], alone.response[b]);
  }
}

// Slot k deposits weight x (a_k / a_max)^n after n collisions. Orders 1 and 2
// (before the roulette plays) are linear and quadratic in the albedo for the
// same photons: the field of a smaller albedo is (s F1 + s^2 F2) with s = a_k /
// a_max, F1 the largest albedo's first order and F2 its second, up to the
// fixed-point rounding of each deposit. Both ways of depositing are checked:
// orders kept apart and weighted after the pass (buckets), and weighted
// deposits per albedo (no buckets, or order 2 beyond them).
TEST(DiffuseBakeShared, EachOrderIsWeightedByTheAlbedoRatioToItsPower) {
 for (int buckets : {0, 1, 4}) {
  SCOPED_TRACE("order buckets " + std::to_string(buckets));
  const SharedCase c;
  DiffuseBakeOptions o;
  o.photons = 20000;
  o.cells = 6;
  o.max_orders = 1;
  const float a_max = 0.9f, a = 0.45f;
  const DiffuseField f1 = bake_diffuse(c.grid, c.bands(a_max, a_max), c.stars, o, Backend::Cpu);
  o.max_orders = 2;
  const DiffuseField f12 = bake_diffuse(c.grid, c.bands(a_max, a_max), c.stars, o, Backend::Cpu);
  o.shared_order_buckets = buckets;
  const std::vector<DiffuseField> shared =
      bake_diffuse_shared(c.grid, {c.bands(a_max, a_max), c.bands(a, a_max)}, c.stars, o, Backend::Cpu);
  const double s = double(a) / a_max;
  for (size_t b = 0; b < 2; ++b) {
    const std::vector<float> one = f1.band_coeffs(b), both = f12.band_coeffs(b), got = shared[1].band_coeffs(b);
    const double scale = b == 0 ? s : 1.0;  // band V keeps a_max in both sets
    double err = 0, norm = 0, second = 0;
    for (size_t i = 0; i < got.size(); ++i) {
      const double f2 = double(both[i]) - one[i];
      const double expected = scale * one[i] + scale * scale * f2;
      err = std::max(err, std::fabs(got[i] - expected));
      norm = std::max(norm, std::fabs(expected));
      second = std::max(second, std::fabs(f2));
    }
    ASSERT_GT(second, 0.05 * norm) << "the second order must weigh in for the test to mean anything";
    EXPECT_LT(err, 1e-5 * norm) << "band " << b;
  }
  EXPECT_EQ(shared[0].band_coeffs(0), f12.band_coeffs(0)) << "the traced albedo's set is the plain bake";
 }
}

// The bucket count changes where an order's deposits are weighted (after the
// pass, in double, or per deposit, in float), not the field: 8 and
// kMaxOrderBuckets buckets give the same fields up to rounding. Auto takes 8
// on the CPU and, on CUDA, as many as kSharedBucketBytes holds.
TEST(DiffuseBakeShared, BucketCountsGiveTheSameFields) {
  const SharedCase c;
  DiffuseBakeOptions o;
  o.photons = 20000;
  o.cells = 6;
  const std::vector<std::vector<DiffuseBand>> sets{c.bands(0.95f, 0.95f), c.bands(0.3f, 0.6f), c.bands(0.6f, 0.4f)};
  o.shared_order_buckets = 8;
  const std::vector<DiffuseField> few = bake_diffuse_shared(c.grid, sets, c.stars, o, Backend::Cpu);
  o.shared_order_buckets = kMaxOrderBuckets;
  const std::vector<DiffuseField> many = bake_diffuse_shared(c.grid, sets, c.stars, o, Backend::Cpu);
  for (size_t s = 0; s < sets.size(); ++s)
    for (size_t b = 0; b < 2; ++b) {
      const std::vector<float> x = few[s].band_coeffs(b), y = many[s].band_coeffs(b);
      ASSERT_EQ(x.size(), y.size());
      double err = 0, norm = 0;
      for (size_t i = 0; i < x.size(); ++i) {
        err = std::max(err, std::fabs(double(x[i]) - y[i]));
        norm = std::max(norm, std::fabs(double(x[i])));
      }
      ASSERT_GT(norm, 0.0);
      EXPECT_LT(err, 1e-5 * norm) << "set " << s << " band " << b;
    }
  DiffuseBakeOptions automatic;
  EXPECT_EQ(shared_order_buckets_for(automatic, Backend::Cpu, 64 * 64 * 64, 25), 8);
  EXPECT_EQ(shared_order_buckets_for(automatic, Backend::Cuda, 64 * 64 * 64, 25), kMaxOrderBuckets);
  EXPECT_EQ(shared_order_buckets_for(automatic, Backend::Cuda, 256 * 256 * 256, 25), 8);
  const size_t cells = 64 * 64 * 64;
  const int by_budget = int(kSharedBucketBytes / (cells * 37 * sizeof(unsigned long long)));
  EXPECT_EQ(shared_order_buckets_for(automatic, Backend::Cuda, cells, 37), by_budget);
  automatic.shared_order_buckets = 3;
  EXPECT_EQ(shared_order_buckets_for(automatic, Backend::Cuda, cells, 25), 3);
}

// Every order, roulette included: the shared estimate of a smaller albedo's
// field against bakes of its own, over independent seeds. The statistic is the
// field's total (l = 0 over all cells) and the tolerance 4 standard errors of
// the mean difference.
TEST(DiffuseBakeShared, SmallerAlbedosAgreeWithBakesOfTheirOwn) {
 for (int buckets : {0, 4}) {
  SCOPED_TRACE("order buckets " + std::to_string(buckets));
  const SharedCase c;
  DiffuseBakeOptions o;
  o.shared_order_buckets = buckets;
  o.photons = 20000;
  o.cells = 6;
  const int runs = 12;
  std::vector<double> diff[2];
  double total[2] = {0, 0};
  for (int run = 0; run < runs; ++run) {
    o.seed = 200 + run;
    const std::vector<DiffuseField> shared =
        bake_diffuse_shared(c.grid, {c.bands(0.95f, 0.95f), c.bands(0.3f, 0.6f)}, c.stars, o, Backend::Cpu);
    o.seed = 900 + run;
    const DiffuseField own = bake_diffuse(c.grid, c.bands(0.3f, 0.6f), c.stars, o, Backend::Cpu);
    for (size_t b = 0; b < 2; ++b) {
      const std::vector<float> x = shared[1].band_coeffs(b), y = own.band_coeffs(b);
      double sx = 0, sy = 0;
      for (size_t i = 0; i < x.size(); i += size_t(own.n_coeffs())) {
        sx += x[i];
        sy += y[i];
      }
      diff[b].push_back(sx - sy);
      total[b] += sy / runs;
    }
  }
  for (size_t b = 0; b < 2; ++b) {
    double mean = 0, var = 0;
    for (double d : diff[b]) mean += d / runs;
    for (double d : diff[b]) var += (d - mean) * (d - mean) / (runs - 1);
    const double se = std::sqrt(var / runs);
    std::printf("band %zu: shared - own total %.4g +- %.2g (total %.4g, %+.2f%%)\n", b, mean, se, total[b],
                100 * mean / total[b]);
    EXPECT_GT(se, 0.0);
    EXPECT_LT(se, 0.02 * total[b]) << "too few photons for the test to mean anything";
    EXPECT_LT(std::fabs(mean), 4 * se) << "band " << b;
  }
 }
}

TEST(DiffuseBakeShared, RefusesSetsThatDifferBeyondTheAlbedo) {
  const SharedCase c;
  DiffuseBakeOptions o;
  o.photons = 1000;
  std::vector<DiffuseBand> other_g = c.bands(0.5f, 0.5f);
  other_g[1].g = 0.3f;
  EXPECT_THROW(bake_diffuse_shared(c.grid, {c.bands(0.5f, 0.5f), other_g}, c.stars, o, Backend::Cpu), Error);
  std::vector<DiffuseBand> other_ratio = c.bands(0.5f, 0.5f);
  other_ratio[0].extinction_ratio = 1.3f;
  EXPECT_THROW(bake_diffuse_shared(c.grid, {c.bands(0.5f, 0.5f), other_ratio}, c.stars, o, Backend::Cpu), Error);
  const std::vector<std::vector<DiffuseBand>> too_many(kMaxAlbedoSlots + 1, c.bands(0.5f, 0.5f));
  EXPECT_THROW(bake_diffuse_shared(c.grid, too_many, c.stars, o, Backend::Cpu), Error);
}

// A set whose band does not scatter gets no field there, as a bake of its own.
TEST(DiffuseBakeShared, AnAlbedoOfZeroGetsNoField) {
  const SharedCase c;
  DiffuseBakeOptions o;
  o.photons = 2000;
  o.cells = 6;
  std::vector<DiffuseBakeStats> stats;
  const std::vector<DiffuseField> f =
      bake_diffuse_shared(c.grid, {c.bands(0.0f, 0.7f), c.bands(0.4f, 0.7f)}, c.stars, o, Backend::Cpu, &stats);
  EXPECT_TRUE(f[0].response[0].empty());
  EXPECT_EQ(stats[0].noise[0], -1.0);
  for (float v : f[0].band_coeffs(0)) ASSERT_EQ(v, 0.0f);
  EXPECT_FALSE(f[1].response[0].empty());
  EXPECT_EQ(f[0].band_coeffs(1), f[1].band_coeffs(1));  // band V: the same albedo, the same deposits
}

// Hard cases: a star at a voxel corner and one inside a voxel of tau 1000,
// g = +-0.99, albedo 1 and 0, an empty grid: every coefficient finite, and
// nothing at all where nothing scatters.
TEST(DiffuseBake, HardCasesStayFinite) {
  DensityGrid grid = cube(8, 0.5f);
  grid.tau_v[grid.shape.index(4, 4, 4)] = 1000.0f;
  const DensityGrid empty = cube(8, 0.0f);
  DiffuseBakeOptions o;
  o.photons = 2000;
  for (float g : {-0.99f, 0.0f, 0.99f})
    for (float albedo : {0.0f, 0.5f, 1.0f})
      for (Vec3 star : {Vec3{0.0f, 0.0f, 0.0f}, Vec3{0.1f, 0.1f, 0.1f}, Vec3{3.0f, 0.2f, -0.1f}})
        for (const DensityGrid* d : {static_cast<const DensityGrid*>(&grid), &empty}) {
          const ScatteringTable table = thin_table(g);
          const DiffuseBand band = v_band(albedo, g, table);
          DiffuseBakeStats stats;
          const DiffuseField f = bake_diffuse(*d, {band}, {{star, {10.0f}}}, o, Backend::Cpu, &stats);
          const std::vector<float> c = f.band_coeffs(0);
          if (albedo == 0 || d == &empty) {
            for (float v : c) ASSERT_EQ(v, 0.0f);
            continue;
          }
          double fluence = 0;
          for (size_t i = 0; i < c.size(); ++i) {
            ASSERT_TRUE(std::isfinite(c[i])) << "g " << g << " albedo " << albedo;
            if (i % size_t(f.n_coeffs()) == 0) fluence += c[i];
          }
          EXPECT_GT(fluence, 0.0) << "g " << g << " albedo " << albedo;
        }
}

}  // namespace
}  // namespace nebula
