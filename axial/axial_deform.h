#pragma once
// Asymmetry for axial maps (Khalass 2021, section 3.2; docs/axial.md,
// "Asymmetry"), host and device:
//
//  * colour deformations: per band b a 3D noise field c_b(q) = 1 - A n_b(q)
//    in [1 - A, 1] multiplies the band's emission and extinction (and the
//    light its dust scatters) at the sample's point q; it only lowers them,
//    so an empty texel stays empty and the skip structures stay true;
//  * shape deformations: a displacement map d(ix, phi) in [0, d_max] over the
//    map's columns and the angle around the axis; a sample at distance r from
//    the axis reads the texel at r (1 - d): it is pulled towards the axis by a
//    fraction of its distance. The map is baked on the host from the noise on
//    the map's outer cylinder and read by linear interpolation in the angle.
//
// The angle is the "diamond angle" (a monotone stand-in for atan2: no
// transcendental function, the same on both backends): for the sample's
// offset (u, v) from the axis in a fixed frame, p = u / (|u| + |v|) and
// a = 1 - p (v >= 0) or 3 + p (v < 0), a in [0, 4).
#include <cstdint>
#include <string>
#include <vector>

#include "axial/axial_noise.h"
#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

constexpr int kAxialShapeAngles = 256;  // displacement map bins around the axis

// What a scene asks for ([axial.colour_deform], [axial.shape_deform]).
struct AxialDeformSettings {
  bool colour = false;
  NoiseParams colour_noise;
  bool shape = false;
  NoiseParams shape_noise;
  bool any() const { return colour || shape; }
};

// The kernel's view, by value.
struct AxialDeformView {
  bool colour = false;
  NoiseParams colour_noise;
  float inv_length = 1.0f;  // colour noise coordinates: q / L (L the map's length)
  bool shape = false;
  float d_max = 0.0f;        // the largest pull (shape_noise.amplitude)
  float shrink = 1.0f;       // 1 - d_max: a sample at r reads r' in [r shrink, r]
  const float* pull = nullptr;  // [ix * kAxialShapeAngles + bin], in [0, d_max]
  Vec3 e1{1, 0, 0}, e2{0, 1, 0};  // frame perpendicular to the axis: the angle's zero and quarter turn
};

// The colour factors of the first n_bands bands at q (relative to the map's
// origin), each in [1 - A, 1]: one noise field per band (noise01_bands).
NEBULA_HD void colour_factors(const AxialDeformView& d, Vec3 q, int n_bands, float* out) {
  noise01_bands(d.colour_noise, d.inv_length * q, n_bands, out);
  for (int b = 0; b < 4; ++b)
    if (b < n_bands) out[b] = 1.0f - d.colour_noise.amplitude * out[b];
}

// The diamond angle in [0, 4) of the offset (u, v); 0 on the axis.
NEBULA_HD float diamond_angle(float u, float v) {
  const float s = fabsf(u) + fabsf(v);
  const float p = s > 0.0f ? u / s : 1.0f;
  return v >= 0.0f ? 1.0f - p : 3.0f + p;
}

// The pull d in [0, d_max] of column ix at offset w (perpendicular to the axis).
NEBULA_HD float shape_pull(const AxialDeformView& d, int ix, Vec3 w) {
  const float a = diamond_angle(dot(w, d.e1), dot(w, d.e2)) * (0.25f * float(kAxialShapeAngles));
  const float f = floorf(a);
  int i0 = static_cast<int>(f);
  const float frac = a - f;
  i0 = i0 < 0 ? 0 : (i0 >= kAxialShapeAngles ? kAxialShapeAngles - 1 : i0);
  const int i1 = i0 + 1 == kAxialShapeAngles ? 0 : i0 + 1;
  const float* column = d.pull + static_cast<size_t>(ix) * kAxialShapeAngles;
  const float v = column[i0] + frac * (column[i1] - column[i0]);
  return fminf(d.d_max, fmaxf(0.0f, v));
}

// The displacement map of an nx-column map of length L and radius R about
// `axis`: bin j of column ix holds A noise01 at (x / L, (R / L) cos phi,
// (R / L) sin phi), x the column's centre, phi the angle of bin j's diamond
// angle 4 j / kAxialShapeAngles. Host code.
std::vector<float> bake_shape_pull(const NoiseParams& noise, int nx, float texel, float radius);
// The frame (e1, e2) the angle is measured in for this axis.
void deform_frame(Vec3 axis, Vec3& e1, Vec3& e2);

// Throws Error "<what>.<key>: <reason>" for parameters out of range (the
// scene's keys: frequency > 0, octaves 1-8, gain (0, 1], lacunarity >= 1,
// amplitude [0, 1] for colour, [0, 0.9] for shape).
void check_noise(const NoiseParams& n, bool shape, const std::string& what);
const char* to_string(NoiseKind kind);
bool parse_noise_kind(const std::string& text, NoiseKind& out);

}  // namespace nebula
