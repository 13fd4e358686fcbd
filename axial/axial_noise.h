#pragma once
// Smooth 3D noise for the axial map's deformations (Khalass 2021, section 3.2;
// docs/axial.md, "Asymmetry"), written once for host and device. Every value
// comes from integer hashing of lattice points and float arithmetic, so it is
// deterministic and needs no tables:
//
//  * simplex: Perlin's simplex noise (Perlin 2001, "Noise hardware", Real-Time
//    Shading course notes; as explained by Gustavson 2005, "Simplex noise
//    demystified"): the sum over the 4 corners of the tetrahedron holding p
//    of (0.5 - |d|^2)^4 (g . d), d from the corner to p (the radius^2 0.5 of
//    Perlin's, not Gustavson's 0.6: no corner outside the tetrahedron is
//    within it, so the field is continuous), gradients g the 12
//    cube-edge directions of Perlin 2002 ("Improving noise"), picked by hash.
//  * fbm: fractal Brownian motion, sum over octaves o of gain^o s(lacunarity^o p).
//  * turbulence: the same sum of |s| (Perlin 1985, "An image synthesizer").
//  * cellular: Worley 1996 ("A cellular texture basis function"): F1, the
//    distance to the nearest feature point, one point per unit cell placed by
//    hash (Worley scatters a Poisson number per cell; one is the usual
//    simplification), summed over octaves like fbm.
//
// Every kind is mapped to [0, 1] (noise01). The lattice hash mixes the cell's
// integer coordinates and the seed with the 32-bit finaliser of MurmurHash3
// (Appleby 2011: multiply-xorshift constants, a published fact).
#include <cstdint>

#include "core/hd.h"
#include "core/vec3.h"

namespace nebula {

enum class NoiseKind : int { Simplex = 0, Fbm = 1, Turbulence = 2, Cellular = 3 };

struct NoiseParams {
  NoiseKind kind = NoiseKind::Fbm;
  float frequency = 4.0f;   // features per unit of the noise's coordinates (docs/axial.md: per map length)
  int octaves = 4;          // fbm, turbulence, cellular: 1 to 8
  float gain = 0.5f;        // amplitude ratio between octaves, (0, 1]
  float lacunarity = 2.0f;  // frequency ratio between octaves, >= 1
  float amplitude = 0.5f;   // colour: the largest lowering (0 to 1); shape: the largest pull d_max (0 to 0.9)
  uint32_t seed = 1;
};

// The sum below peaks at |n| = 0.01301 (the largest of 4e6 random points,
// measured): this scale maps it to about [-1, 1] (values are then clamped).
constexpr float kSimplexScale = 76.8f;

namespace noise_detail {

NEBULA_HD uint32_t mix32(uint32_t h) {
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

NEBULA_HD uint32_t lattice_hash(int i, int j, int k, uint32_t seed) {
  uint32_t h = mix32(seed ^ 0x9e3779b9u);
  h = mix32(h ^ static_cast<uint32_t>(i));
  h = mix32(h ^ static_cast<uint32_t>(j) * 0x27d4eb2fu);
  return mix32(h ^ static_cast<uint32_t>(k) * 0x165667b1u);
}

// g . d for the cube-edge gradient (two of +-1, one 0) chosen by h (Perlin 2002).
NEBULA_HD float edge_gradient(uint32_t h, float x, float y, float z) {
  const int c = static_cast<int>(h % 12u);
  const float u = c < 8 ? x : y, v = c < 4 ? y : z;  // 0-3: (x, y), 4-7: (x, z), 8-11: (y, z)
  return ((c & 1) ? -u : u) + ((c & 2) ? -v : v);
}

NEBULA_HD int floor_int(float v) {
  const float f = floorf(v);
  return static_cast<int>(f);
}

}  // namespace noise_detail

// Simplex noise in [-1, 1] (clamped; the unclamped range is about +-1) for
// n_bands (1 to 4) fields at once: they share the lattice and the corners'
// weights; field b takes its corner gradients from byte b of the corner's
// hash, so the fields are independent for the cost of about one. Field 0 is
// simplex3(p, seed).
NEBULA_HD void simplex3_bands(Vec3 p, uint32_t seed, int n_bands, float* out) {
  using namespace noise_detail;
  constexpr float F3 = 1.0f / 3.0f, G3 = 1.0f / 6.0f;  // skew to the cubic lattice and back
  const float s = (p.x + p.y + p.z) * F3;
  const int i = floor_int(p.x + s), j = floor_int(p.y + s), k = floor_int(p.z + s);
  const float t = float(i + j + k) * G3;
  const float x0 = p.x - (float(i) - t), y0 = p.y - (float(j) - t), z0 = p.z - (float(k) - t);
  // Which of the six tetrahedra of the skewed cube: order the offsets.
  int i1, j1, k1, i2, j2, k2;
  if (x0 >= y0) {
    if (y0 >= z0) { i1 = 1; j1 = 0; k1 = 0; i2 = 1; j2 = 1; k2 = 0; }
    else if (x0 >= z0) { i1 = 1; j1 = 0; k1 = 0; i2 = 1; j2 = 0; k2 = 1; }
    else { i1 = 0; j1 = 0; k1 = 1; i2 = 1; j2 = 0; k2 = 1; }
  } else {
    if (y0 < z0) { i1 = 0; j1 = 0; k1 = 1; i2 = 0; j2 = 1; k2 = 1; }
    else if (x0 < z0) { i1 = 0; j1 = 1; k1 = 0; i2 = 0; j2 = 1; k2 = 1; }
    else { i1 = 0; j1 = 1; k1 = 0; i2 = 1; j2 = 1; k2 = 0; }
  }
  const float cx[4] = {x0, x0 - float(i1) + G3, x0 - float(i2) + 2.0f * G3, x0 - 1.0f + 3.0f * G3};
  const float cy[4] = {y0, y0 - float(j1) + G3, y0 - float(j2) + 2.0f * G3, y0 - 1.0f + 3.0f * G3};
  const float cz[4] = {z0, z0 - float(k1) + G3, z0 - float(k2) + 2.0f * G3, z0 - 1.0f + 3.0f * G3};
  const int di[4] = {0, i1, i2, 1}, dj[4] = {0, j1, j2, 1}, dk[4] = {0, k1, k2, 1};
  float n[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int c = 0; c < 4; ++c) {
    float a = 0.5f - cx[c] * cx[c] - cy[c] * cy[c] - cz[c] * cz[c];
    if (a > 0.0f) {
      a *= a;
      a *= a;
      const uint32_t h = lattice_hash(i + di[c], j + dj[c], k + dk[c], seed);
      for (int b = 0; b < 4; ++b)
        if (b < n_bands) n[b] += a * edge_gradient(h >> (8 * b), cx[c], cy[c], cz[c]);
    }
  }
  for (int b = 0; b < 4; ++b)
    if (b < n_bands) out[b] = fminf(1.0f, fmaxf(-1.0f, kSimplexScale * n[b]));
}

NEBULA_HD float simplex3(Vec3 p, uint32_t seed) {
  float v;
  simplex3_bands(p, seed, 1, &v);
  return v;
}

// Worley's F1 in [0, 1]: distance to the nearest of one hashed feature point
// per unit cell, over the 27 cells around p (F1 < 1 always lies among them);
// clamped at 1. For n_bands fields at once: field b places its points with
// its own hash of the cell (field 0: cellular3(p, seed)).
NEBULA_HD void cellular3_bands(Vec3 p, uint32_t seed, int n_bands, float* out) {
  using namespace noise_detail;
  const int i = floor_int(p.x), j = floor_int(p.y), k = floor_int(p.z);
  const float fx = p.x - float(i), fy = p.y - float(j), fz = p.z - float(k);
  float best[4] = {3.0f, 3.0f, 3.0f, 3.0f};
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        uint32_t h = lattice_hash(i + di, j + dj, k + dk, seed);
        for (int b = 0; b < 4; ++b) {
          if (b >= n_bands) break;
          if (b > 0) h = mix32(h + 0x9e3779b9u);
          const uint32_t h2 = mix32(h);
          // The feature point's place in its cell: three 10-bit fractions.
          const float ox = float(h & 1023u) * (1.0f / 1024.0f), oy = float((h >> 10) & 1023u) * (1.0f / 1024.0f),
                      oz = float(h2 & 1023u) * (1.0f / 1024.0f);
          const float ex = float(di) + ox - fx, ey = float(dj) + oy - fy, ez = float(dk) + oz - fz;
          const float d2 = ex * ex + ey * ey + ez * ez;
          best[b] = d2 < best[b] ? d2 : best[b];
        }
      }
  for (int b = 0; b < 4; ++b)
    if (b < n_bands) out[b] = fminf(1.0f, sqrtf(best[b]));
}

NEBULA_HD float cellular3(Vec3 p, uint32_t seed) {
  float v;
  cellular3_bands(p, seed, 1, &v);
  return v;
}

// n_bands (1 to 4) fields of the noise `n` at p (frequency applied here), in
// [0, 1]; field 0 is noise01(n, p). Octaves above 8 are treated as 8.
NEBULA_HD void noise01_bands(const NoiseParams& n, Vec3 p, int n_bands, float* out) {
  p = n.frequency * p;
  const int octaves = n.kind == NoiseKind::Simplex ? 1 : (n.octaves < 1 ? 1 : (n.octaves > 8 ? 8 : n.octaves));
  float sum[4] = {0.0f, 0.0f, 0.0f, 0.0f}, v[4];
  float weight = 0.0f, w = 1.0f;
  for (int o = 0; o < octaves; ++o) {
    const uint32_t seed = n.seed + 0x3c6ef372u * static_cast<uint32_t>(o);  // octaves decorrelated
    if (n.kind == NoiseKind::Cellular) cellular3_bands(p, seed, n_bands, v);
    else simplex3_bands(p, seed, n_bands, v);
    for (int b = 0; b < 4; ++b)
      if (b < n_bands) sum[b] += w * (n.kind == NoiseKind::Turbulence ? fabsf(v[b]) : v[b]);
    weight += w;
    w *= n.gain;
    p = n.lacunarity * p;
  }
  for (int b = 0; b < 4; ++b)
    if (b < n_bands) {
      const float s = sum[b] / weight;  // simplex and fbm in [-1, 1], turbulence and cellular in [0, 1]
      const float u = (n.kind == NoiseKind::Simplex || n.kind == NoiseKind::Fbm) ? 0.5f + 0.5f * s : s;
      out[b] = fminf(1.0f, fmaxf(0.0f, u));
    }
}

// The noise of `n` at p (p in the noise's units before the frequency), in [0, 1].
NEBULA_HD float noise01(const NoiseParams& n, Vec3 p) {
  float v;
  noise01_bands(n, p, 1, &v);
  return v;
}

}  // namespace nebula
