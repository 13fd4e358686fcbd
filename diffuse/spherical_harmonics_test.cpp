#include "diffuse/spherical_harmonics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math.h"
#include "core/philox.h"
#include "diffuse/test_quadrature.h"

namespace nebula {
namespace {

// A product rule exact for polynomials of degree <= 2 x 4 on the sphere.
TEST(SphericalHarmonics, AreOrthonormal) {
  std::vector<double> mu, wmu;
  testing::gauss_legendre(12, -1, 1, mu, wmu);
  const int n_phi = 24;
  double gram[kMaxShCoeffs][kMaxShCoeffs] = {};
  float y[kMaxShCoeffs];
  for (size_t i = 0; i < mu.size(); ++i)
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2 * kPiD * (j + 0.5) / n_phi, s = std::sqrt(1 - mu[i] * mu[i]);
      sh_basis(kMaxShDegree, Vec3{float(s * std::cos(phi)), float(s * std::sin(phi)), float(mu[i])}, y);
      const double w = wmu[i] * 2 * kPiD / n_phi;
      for (int a = 0; a < kMaxShCoeffs; ++a)
        for (int b = 0; b < kMaxShCoeffs; ++b) gram[a][b] += w * y[a] * y[b];
    }
  for (int a = 0; a < kMaxShCoeffs; ++a)
    for (int b = 0; b < kMaxShCoeffs; ++b) EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 2e-6) << a << ", " << b;
}

TEST(SphericalHarmonics, AddUpToLegendrePolynomials) {
  float ya[kMaxShCoeffs], yb[kMaxShCoeffs];
  double p[kMaxShDegree + 1];
  for (uint32_t t = 0; t < 200; ++t) {
    const Uniform4 u = philox_uniform4(7, 0, t, 0, 0);
    auto direction = [](float a, float b) {
      const float z = 1 - 2 * a, s = std::sqrt(1 - z * z), phi = 2 * kPi * b;
      return Vec3{s * std::cos(phi), s * std::sin(phi), z};
    };
    const Vec3 a = direction(u.u0, u.u1), b = direction(u.u2, u.u3);
    sh_basis(kMaxShDegree, a, ya);
    sh_basis(kMaxShDegree, b, yb);
    legendre(kMaxShDegree, dot(a, b), p);
    for (int l = 0; l <= kMaxShDegree; ++l) {
      double sum = 0;
      for (int k = l * l; k < (l + 1) * (l + 1); ++k) sum += double(ya[k]) * yb[k];
      EXPECT_NEAR(sum, (2 * l + 1) / (4 * kPiD) * p[l], 2e-6) << "l = " << l;
    }
  }
}

// Zonal harmonics about z are the m = 0 harmonics of sh_basis, and about any
// axis they stay orthonormal up to kMaxZonalDegree (Gauss-Legendre in mu,
// exact for the products' degree).
TEST(SphericalHarmonics, ZonalBasisIsTheAxialHarmonicsToItsLastDegree) {
  float y[kMaxShCoeffs], z[kMaxZonalDegree + 1];
  for (float mu : {-1.0f, -0.4f, 0.0f, 0.3f, 0.95f, 1.0f}) {
    const float s = std::sqrt(std::max(0.0f, 1 - mu * mu));
    sh_basis(kMaxShDegree, Vec3{0.6f * s, 0.8f * s, mu}, y);
    zonal_basis(0, kMaxShDegree, mu, z);
    for (int l = 0; l <= kMaxShDegree; ++l) EXPECT_NEAR(z[l], y[l * l + l], 2e-6) << "mu " << mu << " l " << l;
    float tail[kMaxZonalDegree];
    zonal_basis(3, kMaxZonalDegree, mu, tail);  // a later first degree: the same values, shifted
    for (int l = 3; l <= kMaxShDegree; ++l) EXPECT_EQ(tail[l - 3], z[l]);
  }
  std::vector<double> mu, w;
  testing::gauss_legendre(40, -1, 1, mu, w);
  double gram[kMaxZonalDegree + 1][kMaxZonalDegree + 1] = {};
  for (size_t i = 0; i < mu.size(); ++i) {
    zonal_basis(0, kMaxZonalDegree, float(mu[i]), z);
    for (int a = 0; a <= kMaxZonalDegree; ++a)
      for (int b = 0; b <= kMaxZonalDegree; ++b) gram[a][b] += 2 * kPiD * w[i] * z[a] * z[b];
  }
  for (int a = 0; a <= kMaxZonalDegree; ++a)
    for (int b = 0; b <= kMaxZonalDegree; ++b) EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 2e-5) << a << ", " << b;
}

TEST(SphericalHarmonics, LegendreMatchesItsClosedForms) {
  double p[5];
  for (double mu : {-1.0, -0.3, 0.0, 0.5, 1.0}) {
    legendre(4, mu, p);
    EXPECT_NEAR(p[2], 0.5 * (3 * mu * mu - 1), 1e-15);
    EXPECT_NEAR(p[3], 0.5 * (5 * mu * mu * mu - 3 * mu), 1e-15);
    EXPECT_NEAR(p[4], (35 * std::pow(mu, 4) - 30 * mu * mu + 3) / 8, 1e-15);
  }
  for (int k = 0; k < 25; ++k) EXPECT_EQ(sh_degree_of(k), int(std::sqrt(double(k))));
}

// Turning the frame by phi about z: the harmonics of a direction seen from
// the turned frame are the turned harmonics of the direction, for every
// degree and angle (the relation the axial field's meridian frames rely on).
TEST(SphericalHarmonics, TurnAboutTheZAxis) {
  float y[kMaxShCoeffs], turned[kMaxShCoeffs], local[kMaxShCoeffs];
  for (uint32_t t = 0; t < 100; ++t) {
    const Uniform4 u = philox_uniform4(11, 0, t, 0, 0);
    const float z = 1 - 2 * u.u0, s = std::sqrt(1 - z * z), psi = 2 * kPi * u.u1, phi = 2 * kPi * u.u2;
    const Vec3 d{s * std::cos(psi), s * std::sin(psi), z};
    // d in the frame whose x axis is (cos phi, sin phi, 0).
    const Vec3 d_local{s * std::cos(psi - phi), s * std::sin(psi - phi), z};
    for (int degree = 0; degree <= kMaxShDegree; ++degree) {
      sh_basis(degree, d, y);
      sh_basis(degree, d_local, local);
      sh_rotate_z(degree, std::cos(phi), std::sin(phi), y, turned);
      for (int k = 0; k < sh_count(degree); ++k) EXPECT_NEAR(turned[k], local[k], 2e-5f) << "degree " << degree << " k " << k;
    }
  }
}

}  // namespace
}  // namespace nebula
