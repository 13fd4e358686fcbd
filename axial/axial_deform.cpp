#include "axial/axial_deform.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/math.h"

namespace nebula {

void deform_frame(Vec3 axis, Vec3& e1, Vec3& e2) { orthonormal_frame(axis, e1, e2); }

std::vector<float> bake_shape_pull(const NoiseParams& noise, int nx, float texel, float radius) {
  std::vector<float> pull(size_t(nx) * kAxialShapeAngles);
  const double length = double(nx) * texel, ring = double(radius) / length;
  for (int j = 0; j < kAxialShapeAngles; ++j) {
    // The point of diamond angle a on the diamond |u| + |v| = 1, then its angle.
    const double a = 4.0 * j / kAxialShapeAngles;
    const double p = a < 2.0 ? 1.0 - a : a - 3.0;
    const double u = p, v = (a < 2.0 ? 1.0 : -1.0) * (1.0 - std::fabs(p));
    const double phi = std::atan2(v, u);
    for (int ix = 0; ix < nx; ++ix) {
      const Vec3 q{float((ix + 0.5) * texel / length), float(ring * std::cos(phi)), float(ring * std::sin(phi))};
      pull[size_t(ix) * kAxialShapeAngles + size_t(j)] = noise.amplitude * noise01(noise, q);
    }
  }
  return pull;
}

const char* to_string(NoiseKind kind) {
  switch (kind) {
    case NoiseKind::Simplex: return "simplex";
    case NoiseKind::Fbm: return "fbm";
    case NoiseKind::Turbulence: return "turbulence";
    case NoiseKind::Cellular: return "cellular";
  }
  return "?";
}

bool parse_noise_kind(const std::string& text, NoiseKind& out) {
  for (NoiseKind k : {NoiseKind::Simplex, NoiseKind::Fbm, NoiseKind::Turbulence, NoiseKind::Cellular})
    if (text == to_string(k)) {
      out = k;
      return true;
    }
  return false;
}

void check_noise(const NoiseParams& n, bool shape, const std::string& what) {
  auto fail = [&](const char* key, const std::string& reason) { throw Error(what + "." + key + ": " + reason); };
  if (!(n.frequency > 0.0f) || !std::isfinite(n.frequency))
    fail("frequency", "is " + to_text(n.frequency) + "; must be finite and > 0");
  if (n.octaves < 1 || n.octaves > 8) fail("octaves", "is " + std::to_string(n.octaves) + "; must be 1 to 8");
  if (!(n.gain > 0.0f && n.gain <= 1.0f)) fail("gain", "is " + to_text(n.gain) + "; must be in (0, 1]");
  if (!(n.lacunarity >= 1.0f) || !std::isfinite(n.lacunarity))
    fail("lacunarity", "is " + to_text(n.lacunarity) + "; must be finite and >= 1");
  const float top = shape ? 0.9f : 1.0f;
  if (!(n.amplitude >= 0.0f && n.amplitude <= top))
    fail("amplitude", "is " + to_text(n.amplitude) + "; must be in [0, " + (shape ? "0.9" : "1") + "]" +
                          (shape ? " (the largest pull towards the axis, a fraction of the distance)" : ""));
}

}  // namespace nebula
