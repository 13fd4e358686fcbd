// Asymmetry (Khalass 2021 section 3.2): the noise kinds against their
// definitions, the displacement map, the effect of each deformation against
// a bound derived from it, and every skipping mode bit-identical to the naive
// march with deformations on.
#include "axial/axial_deform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "axial/axial_test_scenes.h"
#include "core/error.h"

namespace nebula {
namespace {

using testing::AxialScene;

constexpr NoiseKind kKinds[] = {NoiseKind::Simplex, NoiseKind::Fbm, NoiseKind::Turbulence, NoiseKind::Cellular};

bool identical(const Image& a, const Image& b) {
  return a.pixels.size() == b.pixels.size() &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

double peak(const Image& im) {
  double p = 0;
  for (float v : im.pixels) p = std::max(p, double(std::fabs(v)));
  return p;
}

// Simplex noise by its definition, without choosing a tetrahedron: the sum
// over every lattice vertex near p of (0.5 - |d|^2)^4 (g . d) where positive,
// d the unskewed offset from the vertex. Equal to simplex3 when only the
// corners of p's tetrahedron lie within the radius (what makes it continuous).
float simplex_by_definition(Vec3 p, uint32_t seed, int band = 0) {
  const float s = (p.x + p.y + p.z) / 3.0f;
  const int i0 = int(std::floor(p.x + s)), j0 = int(std::floor(p.y + s)), k0 = int(std::floor(p.z + s));
  double n = 0;
  for (int i = i0 - 2; i <= i0 + 2; ++i)
    for (int j = j0 - 2; j <= j0 + 2; ++j)
      for (int k = k0 - 2; k <= k0 + 2; ++k) {
        const double t = (i + j + k) / 6.0;
        const double dx = p.x - (i - t), dy = p.y - (j - t), dz = p.z - (k - t);
        const double a = 0.5 - dx * dx - dy * dy - dz * dz;
        if (a <= 0) continue;
        n += a * a * a * a *
             noise_detail::edge_gradient(noise_detail::lattice_hash(i, j, k, seed) >> (8 * band), float(dx), float(dy),
                                         float(dz));
      }
  return float(std::fmax(-1.0, std::fmin(1.0, kSimplexScale * n)));
}

TEST(AxialNoise, SimplexIsTheSumOverItsCorners) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f);
  for (int n = 0; n < 20000; ++n) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    ASSERT_NEAR(simplex3(p, 11), simplex_by_definition(p, 11), 2e-5f) << p.x << " " << p.y << " " << p.z;
    // The per-band fields: each its own gradients (byte b of the corner's hash).
    float bands[4];
    simplex3_bands(p, 11, 4, bands);
    for (int b = 0; b < 4; ++b) ASSERT_NEAR(bands[b], simplex_by_definition(p, 11, b), 2e-5f) << b;
  }
}

// The per-band colour fields differ from each other (independent gradients),
// and field 0 of every kind is the single field.
TEST(AxialNoise, BandFieldsAreDistinct) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  for (NoiseKind kind : kKinds) {
    NoiseParams n;
    n.kind = kind;
    int differs = 0;
    for (int i = 0; i < 1000; ++i) {
      const Vec3 p{u(rng), u(rng), u(rng)};
      float v[4];
      noise01_bands(n, p, 4, v);
      ASSERT_EQ(v[0], noise01(n, p)) << to_string(kind);
      differs += v[1] != v[0] && v[2] != v[0] && v[3] != v[1];
    }
    EXPECT_GT(differs, 900) << to_string(kind);
  }
}

// Every kind lies in [0, 1], is deterministic, depends on the seed, spreads
// over its range, and is continuous: over a step of 1e-4 (in noise units) the
// change stays below a Lipschitz bound (simplex: |grad| <= scale * 4 corners *
// max |d((0.5-d^2)^4 g.d)| < 200 per unit; cellular F1 is 1-Lipschitz; fbm
// and turbulence add octaves of lacunarity^o times that, weighted by gain^o).
TEST(AxialNoise, EveryKindIsBoundedDeterministicAndContinuous) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  for (NoiseKind kind : kKinds) {
    NoiseParams n;
    n.kind = kind;
    n.frequency = 3.0f;
    double lo = 1, hi = 0, sum = 0;
    int differs = 0;
    const int count = 20000;
    for (int i = 0; i < count; ++i) {
      const Vec3 p{u(rng), u(rng), u(rng)};
      const float v = noise01(n, p);
      ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << to_string(kind) << " " << v;
      ASSERT_EQ(v, noise01(n, p));
      NoiseParams other = n;
      other.seed = 2;
      differs += noise01(other, p) != v;
      lo = std::min(lo, double(v));
      hi = std::max(hi, double(v));
      sum += v;
      const float step = 1e-4f / n.frequency;
      double lipschitz = kind == NoiseKind::Cellular ? 1.0 : 200.0;
      if (kind != NoiseKind::Simplex) lipschitz *= 1 + 1 + 1 + 1;  // 4 octaves, lacunarity^o gain^o = 1 each
      EXPECT_LE(std::fabs(noise01(n, p + Vec3{step, 0, 0}) - v), lipschitz * 1e-4 + 1e-6) << to_string(kind);
    }
    EXPECT_GT(differs, count * 9 / 10) << to_string(kind);
    EXPECT_LT(lo, 0.35) << to_string(kind);
    EXPECT_GT(hi, 0.65) << to_string(kind);
    const double mean = sum / count;
    EXPECT_GT(mean, 0.1) << to_string(kind);
    EXPECT_LT(mean, 0.9) << to_string(kind);
  }
}

// Worley's F1 by brute force: the nearest feature point over a 5^3 block of
// cells (one hashed point each) is what cellular3 finds among 27.
TEST(AxialNoise, CellularIsTheDistanceToTheNearestFeaturePoint) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  for (int n = 0; n < 3000; ++n) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    const int i0 = int(std::floor(p.x)), j0 = int(std::floor(p.y)), k0 = int(std::floor(p.z));
    double best = 1e9;
    for (int i = i0 - 2; i <= i0 + 2; ++i)
      for (int j = j0 - 2; j <= j0 + 2; ++j)
        for (int k = k0 - 2; k <= k0 + 2; ++k) {
          const uint32_t h = noise_detail::lattice_hash(i, j, k, 4), h2 = noise_detail::mix32(h);
          const double fx = i + (h & 1023u) / 1024.0, fy = j + ((h >> 10) & 1023u) / 1024.0,
                       fz = k + (h2 & 1023u) / 1024.0;
          best = std::min(best, std::sqrt((fx - p.x) * (fx - p.x) + (fy - p.y) * (fy - p.y) + (fz - p.z) * (fz - p.z)));
        }
    ASSERT_NEAR(cellular3(p, 4), std::min(best, 1.0), 1e-5);
  }
}

TEST(AxialDeform, DiamondAngleIsMonotoneAroundTheAxis) {
  float previous = -1;
  for (int j = 0; j < 3600; ++j) {
    const double phi = 2 * kPiD * j / 3600.0;
    const float a = diamond_angle(float(std::cos(phi)), float(std::sin(phi)));
    ASSERT_GE(a, 0.0f);
    ASSERT_LT(a, 4.0f);
    ASSERT_GT(a, previous) << phi;  // strictly increasing from phi = 0 (a = 0)
    previous = a;
  }
  EXPECT_FLOAT_EQ(diamond_angle(0, 1), 1.0f);
  EXPECT_FLOAT_EQ(diamond_angle(-1, 0), 2.0f);
  EXPECT_FLOAT_EQ(diamond_angle(0, -1), 3.0f);
}

// The displacement map holds A noise01 at each bin's angle on the outer
// cylinder; shape_pull reads a bin's value exactly at the bin's angle, stays
// within [0, d_max] in between, and is periodic around the axis.
TEST(AxialDeform, DisplacementMapIsTheNoiseOnTheOuterCylinder) {
  NoiseParams n;
  n.amplitude = 0.3f;
  const int nx = 8;
  const float texel = 0.1f, radius = 0.4f;
  const std::vector<float> pull = bake_shape_pull(n, nx, texel, radius);
  ASSERT_EQ(pull.size(), size_t(nx) * kAxialShapeAngles);
  AxialDeformView d;
  d.shape = true;
  d.d_max = n.amplitude;
  d.pull = pull.data();
  d.e1 = {1, 0, 0};
  d.e2 = {0, 1, 0};
  const float L = nx * texel;
  for (int ix = 0; ix < nx; ++ix) {
    // Bin 0 is phi = 0, bin 64 a quarter turn (diamond angle 1).
    const float want0 = n.amplitude * noise01(n, Vec3{(ix + 0.5f) * texel / L, radius / L, 0});
    EXPECT_NEAR(shape_pull(d, ix, Vec3{0.7f, 0, 0}), want0, 1e-6f);
    const float want64 = n.amplitude * noise01(n, Vec3{(ix + 0.5f) * texel / L, 0, radius / L});
    EXPECT_NEAR(shape_pull(d, ix, Vec3{0, 0.2f, 0}), want64, 1e-6f);
    for (int j = 0; j < 720; ++j) {
      const double phi = 2 * kPiD * j / 720.0;
      const float v = shape_pull(d, ix, Vec3{float(std::cos(phi)), float(std::sin(phi)), 0});
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, n.amplitude);
    }
    // Just below a full turn the pull approaches bin 0's value (periodic).
    EXPECT_NEAR(shape_pull(d, ix, Vec3{1.0f, -1e-6f, 0}), want0, 1e-4f);
  }
}

// Deformations with amplitude 0 change nothing, bit for bit.
TEST(AxialDeform, ZeroAmplitudeIsTheUndeformedImage) {
  AxialScene s("lopsided", 40, 16);
  s.inputs.camera = s.view(50, 24, 0);
  s.inputs.skip = AxialSkip::Naive;
  const Image plain = render_axial_cpu(s.inputs, nullptr);
  s.inputs.deform.colour = s.inputs.deform.shape = true;
  s.inputs.deform.colour_noise.amplitude = 0;
  s.inputs.deform.shape_noise.amplitude = 0;
  EXPECT_TRUE(identical(render_axial_cpu(s.inputs, nullptr), plain));
}

// Colour: without dust (emission only) each band's radiance is the sum of
// j c_b over the samples with c_b in [1 - A, 1], so every pixel lies between
// (1 - A) and 1 times the undeformed one (to float rounding), and the image
// does change.
TEST(AxialDeform, ColourLowersEmissionWithinItsAmplitude) {
  for (NoiseKind kind : kKinds) {
    AxialScene s("shells", 48, 20, normalize(Vec3{1, 2, 3}), 0.0f);
    std::fill(s.map.tau_v.begin(), s.map.tau_v.end(), 0.0f);
    for (auto& e : s.map.emission)
      for (float& v : e) v = v > 0 ? v : 0.0f;
    s.map.update_skip_structures();
    s.inputs.camera = s.view(40, 32, 0);
    const Image plain = render_axial_cpu(s.inputs, nullptr);
    s.inputs.deform.colour = true;
    s.inputs.deform.colour_noise.kind = kind;
    s.inputs.deform.colour_noise.amplitude = 0.6f;
    const Image deformed = render_axial_cpu(s.inputs, nullptr);
    double changed = 0;
    for (size_t i = 0; i < plain.pixels.size(); ++i) {
      const double p = plain.pixels[i], d = deformed.pixels[i];
      ASSERT_LE(d, p * (1 + 1e-5) + 1e-12) << to_string(kind);
      ASSERT_GE(d, p * 0.4 * (1 - 1e-5) - 1e-12) << to_string(kind);
      changed = std::max(changed, std::fabs(p - d));
    }
    EXPECT_GT(changed, 0.05 * peak(plain)) << to_string(kind);
  }
}

// Shape: a solid core r < r0 (5 texels) seen across the axis. A sample at r
// reads r (1 - d) with d <= d_max, so the deformed core reaches out to at
// most r0 / (1 - d_max) and no less than r0: pixels farther out than that
// are black, and some between r0 and it are lit.
TEST(AxialDeform, ShapePullsTheCoreOutwardWithinItsBound) {
  AxialMap m;
  m.nx = 40;
  m.nr = 20;
  m.texel = 0.1f;
  m.origin = {0, 0, 0};
  m.axis = {0, 0, 1};
  m.tau_v.assign(m.count(), 0.0f);
  m.emission.assign(1, std::vector<float>(m.count(), 0.0f));
  for (int ir = 0; ir < 5; ++ir)
    for (int ix = 0; ix < m.nx; ++ix) m.emission[0][m.index(ix, ir)] = 0.01f;
  m.update_skip_structures();
  AxialRenderInputs in;
  in.map = &m;
  in.bands = {AxialRenderBand{{"V", 1.0f, 0.0f}, nullptr}};
  in.deform.shape = true;
  in.deform.shape_noise.amplitude = 0.4f;
  in.deform.shape_noise.frequency = 6.0f;
  CameraSettings cs;
  cs.projection = Projection::Orthographic;
  cs.position = {0, -10, 2};
  cs.look_at = {0, 0, 2};
  cs.up = {0, 0, 1};
  cs.ortho_width = 4.0f;  // x from -2 to 2: 0.02 per pixel at 200 pixels
  cs.width = 200;
  cs.height = 3;
  in.camera = make_camera(cs);
  const Image image = render_axial_cpu(in, nullptr);
  const float r0 = 0.5f, outer = r0 / (1.0f - 0.4f);
  bool lit_beyond_r0 = false;
  for (int x = 0; x < cs.width; ++x) {
    const float offset = std::fabs(-2.0f + (x + 0.5f) * 4.0f / cs.width);  // the ray's distance from the axis
    const float v = image.pixels[size_t(1) * cs.width + x];
    if (offset > outer + 0.01f) {
      EXPECT_EQ(v, 0.0f) << offset;
    }
    if (offset > r0 + 0.02f && v > 0) lit_beyond_r0 = true;
    if (offset < r0 - 0.02f) {
      EXPECT_GT(v, 0.0f) << offset;
    }
  }
  EXPECT_TRUE(lit_beyond_r0);
}

// The exactness of skipping with deformations on: every mode equals the
// naive march bit for bit, for every noise kind as colour and as shape
// deformation (a large pull, d_max = 0.5), on every synthetic map, with a
// star (full physics), orthographic and perspective, several inclinations.
TEST(AxialDeform, EveryModeIsBitIdenticalToTheNaiveMarch) {
  const AxialSkip modes[] = {AxialSkip::Empty,          AxialSkip::GlobalMax,        AxialSkip::Omega,
                             AxialSkip::OmegaMulti,     AxialSkip::Distance,         AxialSkip::ThesisOmegaMax,
                             AxialSkip::ThesisOmegaLarge, AxialSkip::ThesisOmegaMulti};
  for (const std::string& name : synthetic_axial_map_names()) {
    AxialScene s(name, 48, 20);
    for (int variant = 0; variant < 5; ++variant) {
      AxialDeformSettings& d = s.inputs.deform;
      d = AxialDeformSettings{};
      const NoiseKind kind = kKinds[variant % 4];
      d.colour = variant != 1;
      d.shape = variant != 0;
      d.colour_noise.kind = kind;
      d.colour_noise.amplitude = 0.7f;
      d.shape_noise.kind = kKinds[(variant + 1) % 4];
      d.shape_noise.amplitude = variant == 4 ? 0.9f : 0.5f;
      d.shape_noise.seed = 7 + variant;
      for (int inc : {0, 35, 90}) {
        for (float distance : {0.0f, 4.0f}) {
          s.inputs.camera = s.view(inc, 16, distance);
          s.inputs.skip = AxialSkip::Naive;
          const Image naive = render_axial_cpu(s.inputs, nullptr);
          for (float v : naive.pixels) ASSERT_TRUE(std::isfinite(v));
          for (AxialSkip mode : modes) {
            s.inputs.skip = mode;
            EXPECT_TRUE(identical(render_axial_cpu(s.inputs, nullptr), naive))
                << name << ", variant " << variant << ", inclination " << inc << ", "
                << (distance > 0 ? "perspective" : "orthographic") << ", " << to_string(mode);
          }
        }
      }
    }
  }
}

// Skipping still skips with a shape deformation: on the thin map the distance
// mode and the thesis' omega_multi visit a fraction of the naive samples.
TEST(AxialDeform, SkippingStillSkipsWithAPull) {
  AxialScene s("bipolar", 128, 48);
  s.inputs.camera = s.view(45, 32, 0);
  s.inputs.deform.shape = s.inputs.deform.colour = true;
  s.inputs.deform.shape_noise.amplitude = 0.2f;
  AxialRenderStats naive, distance, thesis;
  s.inputs.skip = AxialSkip::Naive;
  render_axial_cpu(s.inputs, &naive);
  s.inputs.skip = AxialSkip::Distance;
  render_axial_cpu(s.inputs, &distance);
  s.inputs.skip = AxialSkip::ThesisOmegaMulti;
  render_axial_cpu(s.inputs, &thesis);
  std::printf("samples: naive %llu, distance %llu, thesis_omega_multi %llu\n", (unsigned long long)naive.samples,
              (unsigned long long)distance.samples, (unsigned long long)thesis.samples);
  EXPECT_LT(distance.samples * 4, naive.samples);
  EXPECT_LT(thesis.samples * 4, naive.samples);
}

TEST(AxialDeform, BadParametersAreRefusedNamingTheKey) {
  auto refused = [](NoiseParams n, bool shape, const std::string& key) {
    try {
      check_noise(n, shape, "axial.shape_deform");
      ADD_FAILURE() << key;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("axial.shape_deform." + key), std::string::npos) << e.what();
    }
  };
  NoiseParams n;
  n.frequency = -1;
  refused(n, false, "frequency");
  n = NoiseParams{};
  n.octaves = 0;
  refused(n, false, "octaves");
  n = NoiseParams{};
  n.gain = 1.5f;
  refused(n, false, "gain");
  n = NoiseParams{};
  n.lacunarity = 0.5f;
  refused(n, false, "lacunarity");
  n = NoiseParams{};
  n.amplitude = 0.95f;
  refused(n, true, "amplitude");  // a shape pull of 95% is refused, a colour lowering of 95% is not
  EXPECT_NO_THROW(check_noise(n, false, "axial.colour_deform"));
  NoiseKind k;
  EXPECT_TRUE(parse_noise_kind("cellular", k));
  EXPECT_EQ(k, NoiseKind::Cellular);
  EXPECT_FALSE(parse_noise_kind("perlin", k));
}

}  // namespace
}  // namespace nebula
