#pragma once
// Real spherical harmonics Y_k(d), k = l^2 + l + m for degree l <= 4 and
// order -l <= m <= l, orthonormal on the unit sphere (integral of Y_j Y_k over
// all directions is delta_jk), and the Legendre polynomials. Written once for
// host and device: the diffuse bake projects photon directions on them, the
// marchers evaluate them towards the eye.
//
// The addition theorem ties them to the Legendre polynomials P_l:
//   sum over m of Y_lm(a) Y_lm(b) = (2l + 1) / (4 pi) P_l(a . b),
// which is what lets a voxel's scattering table act on a field given by its
// harmonics (diffuse_field.h).
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

constexpr int kMaxShDegree = 4;
constexpr int kMaxShCoeffs = (kMaxShDegree + 1) * (kMaxShDegree + 1);

NEBULA_HD constexpr int sh_count(int degree) { return (degree + 1) * (degree + 1); }

// Y_0 .. Y_{(degree+1)^2 - 1} at the unit vector d, into y. The constants are
// sqrt((2l + 1) / (4 pi) (l - |m|)! / (l + |m|)!) times the usual factors
// (sqrt(2) for m != 0), in the Cartesian forms of the associated Legendre
// functions.
NEBULA_HD void sh_basis(int degree, Vec3 d, float* y) {
  const float x = d.x, yy = d.y, z = d.z;
  y[0] = 0.28209479177387814f;
  if (degree < 1) return;
  y[1] = 0.4886025119029199f * yy;
  y[2] = 0.4886025119029199f * z;
  y[3] = 0.4886025119029199f * x;
  if (degree < 2) return;
  const float x2 = x * x, y2 = yy * yy, z2 = z * z;
  y[4] = 1.0925484305920792f * x * yy;
  y[5] = 1.0925484305920792f * yy * z;
  y[6] = 0.31539156525252005f * (3.0f * z2 - 1.0f);
  y[7] = 1.0925484305920792f * x * z;
  y[8] = 0.5462742152960396f * (x2 - y2);
  if (degree < 3) return;
  y[9] = 0.5900435899266435f * yy * (3.0f * x2 - y2);
  y[10] = 2.890611442640554f * x * yy * z;
  y[11] = 0.4570457994644658f * yy * (5.0f * z2 - 1.0f);
  y[12] = 0.3731763325901154f * z * (5.0f * z2 - 3.0f);
  y[13] = 0.4570457994644658f * x * (5.0f * z2 - 1.0f);
  y[14] = 1.445305721320277f * z * (x2 - y2);
  y[15] = 0.5900435899266435f * x * (x2 - 3.0f * y2);
  if (degree < 4) return;
  y[16] = 2.5033429417967046f * x * yy * (x2 - y2);
  y[17] = 1.7701307697799304f * yy * z * (3.0f * x2 - y2);
  y[18] = 0.9461746957575601f * x * yy * (7.0f * z2 - 1.0f);
  y[19] = 0.6690465435572892f * yy * z * (7.0f * z2 - 3.0f);
  y[20] = 0.10578554691520431f * (35.0f * z2 * z2 - 30.0f * z2 + 3.0f);
  y[21] = 0.6690465435572892f * x * z * (7.0f * z2 - 3.0f);
  y[22] = 0.47308734787878004f * (x2 - y2) * (7.0f * z2 - 1.0f);
  y[23] = 1.7701307697799304f * x * z * (x2 - 3.0f * y2);
  y[24] = 0.6258357354491761f * (x2 * (x2 - 3.0f * y2) - y2 * (3.0f * x2 - y2));
}

// The harmonics of a function seen from a frame turned by angle phi about z
// (cos_phi, sin_phi): out_k = integral f(d) Y_k(d') dd, d' the direction d in
// the turned frame, whose azimuth is d's minus phi. Order m > 0 goes with
// cos(m psi), m < 0 with sin(|m| psi) (sh_basis), so each pair (m, -m) turns by
// m phi. The axial field (axial/) stores its harmonics in each meridian's
// frame. `in` and `out` must not overlap.
NEBULA_HD void sh_rotate_z(int degree, float cos_phi, float sin_phi, const float* in, float* out) {
  out[0] = in[0];
  float cm = 1.0f, sm = 0.0f;  // cos(m phi), sin(m phi), by the angle-sum recursion
  for (int m = 1; m <= degree; ++m) {
    const float c = cm * cos_phi - sm * sin_phi;
    sm = sm * cos_phi + cm * sin_phi;
    cm = c;
    for (int l = m; l <= degree; ++l) {
      const int centre = l * l + l;
      out[centre + m] = cm * in[centre + m] + sm * in[centre - m];
      out[centre - m] = cm * in[centre - m] - sm * in[centre + m];
    }
  }
  for (int l = 1; l <= degree; ++l) out[l * l + l] = in[l * l + l];
}

// Zonal harmonics about an axis a: Y_l0(d) = sqrt((2l + 1) / (4 pi)) P_l(a . d),
// for l = first..last into y[0..last - first] (mu = a . d). The diffuse field
// keeps the high degrees of the light streaming away from a star this way,
// about the direction from the star (diffuse_field.h, "zonal").
constexpr int kMaxZonalDegree = 32;
NEBULA_HD void zonal_basis(int first, int last, float mu, float* y) {
  float p_prev = 1.0f, p = mu;  // P_0, P_1
  if (first == 0) y[0] = 0.28209479177387814f;
  if (first <= 1 && last >= 1) y[1 - first] = 0.4886025119029199f * mu;
  for (int l = 1; l < last; ++l) {
    const float next = ((2.0f * l + 1.0f) * mu * p - float(l) * p_prev) / float(l + 1);
    p_prev = p;
    p = next;
    if (l + 1 >= first) y[l + 1 - first] = sqrtf((2.0f * (l + 1) + 1.0f) * 0.07957747154594767f) * p;
  }
}

// The degree l of harmonic k.
NEBULA_HD int sh_degree_of(int k) { return k < 1 ? 0 : (k < 4 ? 1 : (k < 9 ? 2 : (k < 16 ? 3 : 4))); }

// P_0(mu) .. P_n(mu) into p, by Bonnet's recursion (l + 1) P_{l+1} = (2l + 1) mu P_l - l P_{l-1}.
NEBULA_HD void legendre(int n, double mu, double* p) {
  p[0] = 1.0;
  if (n >= 1) p[1] = mu;
  for (int l = 1; l < n; ++l) p[l + 1] = ((2.0 * l + 1.0) * mu * p[l] - l * p[l - 1]) / (l + 1.0);
}

}  // namespace nebula
