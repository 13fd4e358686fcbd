#pragma once
// The fixed-step marcher through an axial map (docs/axial.md), written once
// for host and device: the naive march ("NASR" in Khalass 2021) and four
// exact empty-space skipping modes that only ever leave out samples that are
// provably empty.
//
// Samples. The ray is clipped to the map's cylinder {0 <= x <= L, r <= R}
// (L = nx l, R = nr l); sample k covers [t_in + k h, t_in + (k + 1) h] (the
// last one ends at t_out), is taken at the middle of its chord and reads the
// texel holding it (nearest texel: ix = floor(x / l), ir = floor(r / l)). The
// sample grid depends only on the ray and the map's outer cylinder, never on
// the skipping mode.
//
// Exactness. An empty sample adds T * 0 to the radiance and multiplies T by
// exp(-0) = 1: exact no-ops in floating point. A skip advances by a whole
// number of samples over a stretch of ray shown (with a margin far above
// float rounding) to lie above the height map, so every skipping mode visits
// the same non-empty samples in the same order with the same arithmetic as
// the naive march: the images are bit-identical on one backend.
#include <cfloat>
#include <cmath>
#include <type_traits>

#include "axial/axial_deform.h"
#include "axial/axial_map.h"
#include "core/hd.h"
#include "core/vec3.h"
#include "diffuse/zonal_light.h"
#include "illumination/chord_irradiance.h"
#include "illumination/optical_depth_bake.h"
#include "raycast/ray_march.h"
#include "tables/table_lookup.h"

namespace nebula {

// Naive to OmegaMulti are the project's versions of the thesis' modes,
// ordered: each does everything the previous one does. Distance is ours:
// GlobalMax's clipping, then jumps sized by the distance map (proximity
// clouds) instead of omega attempts. ThesisOmega* are the thesis' modes as
// its sections 3.1 and 5.1.2 define them (docs/axial.md, "The thesis' modes"):
// the height map's emptiness check on every sample, and from an empty sample
// a step of omega_max = t_exit - t_entry, the ray's interval inside the
// largest max-tree node the sample lies above, or a fraction of it; a step
// that fails falls back to the next sample, which is checked again.
enum class AxialSkip : int {
  Naive = 0,       // every sample: texel fetch and shading
  Empty = 1,       // the height and floor maps decide a sample is empty before any texel fetch
  GlobalMax = 2,   // ... and only the samples inside the cylinder of radius H l are visited
  Omega = 3,       // ... and from an empty sample, jump omega_max (the rest) or omega_large = omega_max / 32
  OmegaMulti = 4,  // ... adaptive jumps (doubling on success, halving on failure), range maxima from the max-tree
  Distance = 5,    // GlobalMax, then from every empty sample the longest jump its texel's distance allows
  ThesisOmegaMax = 6,    // the thesis' omega_max: a step of the node's t_exit - t_entry
  ThesisOmegaLarge = 7,  // the thesis' omega_large: a step of omega_max / 32
  ThesisOmegaMulti = 8   // the thesis' omega_multi: omega_max, omega_max / 2, ... omega_max / 32 tried in that order
};

const char* to_string(AxialSkip mode);

// The light scattered between cells a march adds: none, the field's
// harmonics, or the harmonics with zonal degrees (DiffuseView::zonal > 0). A
// kernel of its own each: the zonal code in the harmonics' kernel doubled
// its frame times (H200: 22.4 -> 42.9 ms on the lopsided map).
enum class AxialField : int { None = 0, Harmonics = 1, Zonal = 2 };

struct AxialMarchScene {
  AxialView map;
  int n_bands = 0;
  float extinction_ratio[kMaxBands];
  float albedo[kMaxBands];
  TableView table[kMaxBands];
  const StarView* stars = nullptr;  // on the axis; depth_v per texel [ir * nx + ix]
  int n_stars = 0;
  float step = 1.0f;  // h, world units
  AxialSkip skip = AxialSkip::Distance;
  float min_transmittance = 1e-4f;
  RayFootprint footprint;  // the camera's pixel width along a ray (starlight near a star)
  bool has_diffuse = false;  // light scattered between cells (axial/axial_diffuse.h), per band where baked
  DiffuseView diffuse;       // cells {along the axis, from it, 1}, harmonics in the meridian frames
  AxialDeformView deform;    // colour and shape deformations (axial_deform.h), read by the kDeform kernels
};

// The diffuse field's light a texel of V-band depth tau_v at sample point q
// (relative to the map's origin; x along the axis, r from it) sends towards
// the eye per band, per unit of chord / l, added to `source`; its forward
// peak per band into `peak`. The field is kept in each meridian's frame (x'
// away from the axis, y' around it, z' along it), so the way to the eye is
// turned into that frame first; its zonal degrees (g >= 0.8 by default) are
// about the line from each star, the same in every frame. Evaluated per sample: unlike the grid's
// voxels, a texel is a ring and meets the eye from every side.
template <bool kZonal>
NEBULA_HD void add_axial_diffuse_light(const AxialMarchScene& s, Vec3 q, float x, float r, float tau_v, Vec3 to_eye,
                                       float* source, float* peak) {
  const AxialView& m = s.map;
  const DiffuseView& f = s.diffuse;
  Vec3 e_r, e_phi;
  if (r > 0.0f) {
    e_r = (1.0f / r) * (q - x * m.axis);
    e_phi = cross(m.axis, e_r);
  } else {
    orthonormal_frame(m.axis, e_r, e_phi);  // on the axis the field is symmetric about it: any frame
  }
  const Vec3 local{dot(to_eye, e_r), dot(to_eye, e_phi), dot(to_eye, m.axis)};
  const float inv_edge = 1.0f / f.cells.voxel;
  int cx = static_cast<int>(x * inv_edge), cr = static_cast<int>(r * inv_edge);
  cx = cx < 0 ? 0 : (cx >= f.cells.nx ? f.cells.nx - 1 : cx);
  cr = cr >= f.cells.ny ? f.cells.ny - 1 : cr;
  float D[kMaxBands][kMaxDiffuseDegree + 1];
  const size_t cell = f.cells.index(cx, cr, 0);
  f.project<kMaxDiffuseDegree>(cell, local, D, f.degree);
  if constexpr (kZonal) {
    // The zonal degrees about the direction from each zonal star (on the
    // axis): a scalar per (x, r) cell, the same in every meridian's frame,
    // so the world's directions serve (m.origin + q is the sample's point).
    float light[kMaxBands] = {}, zonal_peak[kMaxBands] = {};
    if (zonal_scattered_light<kMaxDiffuseDegree>(s, f, tau_v, cell, m.origin + q, to_eye, D, light, zonal_peak,
                                                 f.degree)) {
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b)
        if (b < s.n_bands && f.has[b]) {
          source[b] += light[b];
          peak[b] = zonal_peak[b];
        }
      return;
    }
  }
  NEBULA_UNROLL
  for (int b = 0; b < kMaxBands; ++b)
    if (b < s.n_bands && f.has[b]) {
      float p = 0.0f;
      const float light =
          f.scattered<kMaxDiffuseDegree>(b, s.albedo[b] * tau_v * s.extinction_ratio[b], D[b], &p, f.degree);
      source[b] += fmaxf(0.0f, light);  // a truncated series may dip below 0; the light cannot
      peak[b] = p;
    }
}

// The ray in the map's frame: x(t) = x0 + t dx along the axis, and the part
// perpendicular to the axis w(t) = w0 + t wd, r(t) = |w(t)|.
struct AxialRay {
  float x0, dx;
  Vec3 w0, wd;
};

NEBULA_HD AxialRay axial_ray(const AxialView& m, Vec3 origin, Vec3 dir) {
  AxialRay r;
  const Vec3 q = origin - m.origin;
  r.x0 = dot(q, m.axis);
  r.dx = dot(dir, m.axis);
  r.w0 = q - r.x0 * m.axis;
  r.wd = dir - r.dx * m.axis;
  return r;
}

// The ray's parameter interval [t0, t1] (t >= 0) inside the finite cylinder
// {x_lo <= x <= x_hi, r <= radius}; false when it misses (or only touches).
// Robust for rays parallel to the axis (|wd| = 0: inside iff r(0) <= radius),
// rays through the axis, grazing rays (a tiny or empty interval, never NaN)
// and origins inside (t0 = 0). Double precision: once or twice per ray.
NEBULA_HD bool intersect_cylinder(const AxialRay& ray, float x_lo, float x_hi, float radius, float& t0, float& t1) {
  double lo = 0.0, hi = 1e30;
  if (ray.dx == 0.0f) {
    if (!(ray.x0 >= x_lo && ray.x0 <= x_hi)) return false;
  } else {
    double ta = (double(x_lo) - ray.x0) / ray.dx, tb = (double(x_hi) - ray.x0) / ray.dx;
    if (ta > tb) {
      const double s = ta;
      ta = tb;
      tb = s;
    }
    lo = ta > lo ? ta : lo;
    hi = tb < hi ? tb : hi;
  }
  const double A = double(ray.wd.x) * ray.wd.x + double(ray.wd.y) * ray.wd.y + double(ray.wd.z) * ray.wd.z;
  const double B = double(ray.w0.x) * ray.wd.x + double(ray.w0.y) * ray.wd.y + double(ray.w0.z) * ray.wd.z;
  const double C = double(ray.w0.x) * ray.w0.x + double(ray.w0.y) * ray.w0.y + double(ray.w0.z) * ray.w0.z;
  const double c = C - double(radius) * radius;
  if (A < 1e-14) {  // parallel to the axis (|wd| < 1e-7): r does not change along the ray
    if (c > 0.0) return false;
  } else {
    const double disc = B * B - A * c;
    if (!(disc >= 0.0)) return false;
    const double s = sqrt(disc);
    const double q = -(B + (B < 0.0 ? -s : s));  // no cancellation: |q| >= s
    double ra, rb;
    if (q == 0.0) {  // B = 0 and disc = 0: touches at t = 0
      ra = rb = 0.0;
    } else {
      ra = q / A;
      rb = c / q;
    }
    if (ra > rb) {
      const double t = ra;
      ra = rb;
      rb = t;
    }
    lo = ra > lo ? ra : lo;
    hi = rb < hi ? rb : hi;
  }
  if (!(lo < hi)) return false;
  t0 = static_cast<float>(lo);
  t1 = static_cast<float>(hi);
  return t0 < t1;
}

namespace axial_detail {

// Smallest r over t in [ta, tb] (r is convex in t: |w0 + t wd|), as an
// evaluation of |w(t)| at the clamped vertex, so no cancellation.
NEBULA_HD float min_radius(const AxialRay& ray, float ta, float tb) {
  const float A = dot(ray.wd, ray.wd);
  float t = A > 0.0f ? -dot(ray.w0, ray.wd) / A : ta;
  t = t < ta ? ta : (t > tb ? tb : t);
  return length(ray.w0 + t * ray.wd);
}

// Whether every point of the ray with t in [ta, tb], grown by eps on every
// side, lies above the height map or below the floor map of the columns it
// crosses: then every sample there is empty. With shape deformations a
// sample at r reads a texel at some r' in [r shrink, r] (shrink = 1 - d_max):
// above the height map then needs r_min shrink >= h l + eps; below the floor
// needs nothing more (r' <= r). kFloor false: the height map only (the thesis).
template <bool kTree, bool kFloor = true>
NEBULA_HD bool stretch_is_empty(const AxialView& m, const AxialRay& ray, float ta, float tb, float eps,
                                float shrink = 1.0f) {
  ta -= eps;
  tb += eps;
  const float xa = ray.x0 + ta * ray.dx, xb = ray.x0 + tb * ray.dx;
  const float x_min = fminf(xa, xb) - eps, x_max = fmaxf(xa, xb) + eps;
  if (x_max < 0.0f || x_min >= m.length()) return true;
  const float inv = 1.0f / m.texel;
  const float lo_f = fmaxf(floorf(x_min * inv), 0.0f), hi_f = fminf(floorf(x_max * inv), float(m.nx - 1));
  const int lo = static_cast<int>(lo_f), hi = static_cast<int>(hi_f);
  // r is convex along the ray: smallest at the clamped vertex, largest at an end.
  const float r_min = min_radius(ray, ta, tb);
  const float r_max = fmaxf(length(ray.w0 + ta * ray.wd), length(ray.w0 + tb * ray.wd));
  if (kTree) {
    const int h = m.range_max_tree(lo, hi);
    if (h == 0 || r_min * shrink >= h * m.texel + eps) return true;
    return kFloor && r_max + eps <= m.range_min_floor(lo, hi) * m.texel;
  }
  // The scan stops as soon as neither holds.
  bool above = true, below = true;
  for (int i = lo; i <= hi; ++i) {
    if (m.height[i] == 0) continue;  // an empty column
    above = above && r_min * shrink >= m.height[i] * m.texel + eps;
    below = below && kFloor && r_max + eps <= m.floor[i] * m.texel;
    if (!above && !below) return false;
  }
  return true;
}

// How far (along the ray, world units) the ray may go from a sample at
// (x, r) in texel (ix, ir) whose Chebyshev distance to the nearest non-empty
// texel is d >= 1: every texel within d - 1 of (ix, ir) is empty, so every
// point within (d - 1) l of (x, r) in both x and r lies in an empty texel (or
// outside the map). Along the ray x moves at |dx| and r at most at |wd|
// (triangle inequality), so the (x, r) point moves at most at max(|dx|, |wd|)
// in both; eps covers the rounding of the sample positions. Conservative by
// up to a texel (the sample's place inside its texel is not used): on the
// H100 this three-instruction bound beat an exact box slack with map edges,
// 1.27 against 1.43 ms (docs/performance.md).
NEBULA_HD float distance_reach(int d, float texel, float inv_speed, float eps) {
  return (float(d - 1) * texel - eps) * inv_speed;
}

// The thesis' omega_max at a sample at t in column ix whose smallest read
// radius is r_lo: the current max-tree node is the largest node holding ix
// whose height h lies below the sample (h l + eps <= r_lo); its interval is
// the part of the ray inside the node's x-slab and outside the cylinder of
// radius h l / shrink (where no sample can read a non-empty texel of the
// node's columns), clipped to [t_in, t_out]; omega_max = t_exit - t_entry of
// the piece holding t, in whole samples (0 when no node lies below the
// sample). Float arithmetic: the step it suggests is checked before it is
// taken, so its rounding changes speed, never the image.
NEBULA_HD int thesis_omega_max(const AxialView& m, const AxialRay& ray, int ix, float r_lo, float t, float t_in,
                               float t_out, float inv_h, float eps, float shrink) {
  for (int level = m.n_levels - 1; level >= 0; --level) {
    const int node = ix >> level;
    const int height = m.tree[m.level_offset[level] + node];
    if (!(float(height) * m.texel + eps <= r_lo)) continue;
    const int c0 = node << level, c1 = (node + 1) << level;
    const float xa = float(c0) * m.texel, xb = float(c1 < m.nx ? c1 : m.nx) * m.texel;
    float t_entry = t_in, t_exit = t_out;
    if (ray.dx != 0.0f) {
      float ta = (xa - ray.x0) / ray.dx, tb = (xb - ray.x0) / ray.dx;
      if (ta > tb) {
        const float swap = ta;
        ta = tb;
        tb = swap;
      }
      t_entry = fmaxf(t_entry, ta);
      t_exit = fminf(t_exit, tb);
    }
    if (height > 0) {
      // Where the ray is inside the node's cylinder: (ca, cb), the roots of |w0 + t wd| = rho.
      const float rho = float(height) * m.texel / shrink;
      const float A = dot(ray.wd, ray.wd), B = dot(ray.w0, ray.wd), C = dot(ray.w0, ray.w0) - rho * rho;
      const float disc = B * B - A * C;
      if (A > 0.0f && disc > 0.0f) {
        const float root = sqrtf(disc), ca = (-B - root) / A, cb = (-B + root) / A;
        if (t <= ca) t_exit = fminf(t_exit, ca);
        else if (t >= cb) t_entry = fmaxf(t_entry, cb);
        else return 0;  // within rounding of the cylinder: no step
      }
    }
    const float n = floorf((t_exit - t_entry) * inv_h);
    return n >= 1.0f ? static_cast<int>(fminf(n, 1e8f)) : 0;
  }
  return 0;
}

}  // namespace axial_detail

// One ray through the axial map: radiance and transmittance per band. The
// skip mode (s.skip is not read), whether there are stars, the diffuse field's
// kind (s.has_diffuse and s.diffuse.zonal are not read) and whether the scene has
// deformations (kDeform; which ones: s.deform) are fixed at compile time, so
// each kernel holds only what its scene needs (a scene without stars carries
// no table lookups in its registers). With the field, its light adds to the
// texel's source and its forward peak to the texel's transmittance, as in the
// grid marcher (ray_march.h). `visited` (may be null) counts the samples the
// loop stepped through.
//
// Deformations (axial_deform.h, docs/axial.md "Asymmetry"): a shape-deformed
// sample at r reads the texel at r (1 - d), d in [0, d_max], so every
// emptiness proof covers the whole radial interval [r (1 - d_max), r] before
// the pull is looked up: the height test uses its lower end, the floor test
// its upper end, the distance jump the distance map at its middle less half
// its width. The colour factors only lower a non-empty texel's values, so
// they change no proof.
template <AxialSkip kMode, bool kStars, AxialField kField = AxialField::None, bool kDeform = false>
NEBULA_HD RayResult march_axial_ray(const AxialMarchScene& s, Vec3 origin, Vec3 dir, int* visited = nullptr) {
  constexpr bool kDiffuse = kField != AxialField::None;
  RayResult out{};
  for (int b = 0; b < kMaxBands; ++b) out.transmittance[b] = 1.0f;
  const AxialView& m = s.map;
  const AxialRay ray = axial_ray(m, origin, dir);
  float t_in, t_out;
  if (!intersect_cylinder(ray, 0.0f, m.length(), m.radius(), t_in, t_out)) return out;
  const float h = s.step;
  const float span = t_out - t_in;
  const float n_samples = ceilf(span / h);
  if (!(n_samples >= 1.0f) || n_samples > 1e8f) return out;  // NaN guard; validate() bounds the step
  const int K = static_cast<int>(n_samples);
  int k_begin = 0, k_end = K;
  // Geometric margin for skip decisions: far above the rounding of the
  // sample positions (a few ulps of the coordinates' magnitude).
  const float scale = length(origin - m.origin) + t_out + m.length() + m.radius();
  const float eps = 1e-3f * m.texel + 1e-5f * scale;
  constexpr int skip = static_cast<int>(kMode);
  constexpr bool kThesis = skip >= int(AxialSkip::ThesisOmegaMax);
  const AxialDeformView& deform = s.deform;
  const bool shape = kDeform && deform.shape;
  const float shrink = shape ? deform.shrink : 1.0f;  // a sample at r reads r' >= r shrink
  if (skip >= int(AxialSkip::GlobalMax) && !kThesis) {
    if (m.global_max == 0) return out;
    float ta, tb;
    // Beyond r = H l / shrink every read radius r' >= r shrink is above the map.
    const float clip = shape ? m.global_max * m.texel / shrink : m.global_max * m.texel;
    if (!intersect_cylinder(ray, -eps, m.length() + eps, clip + eps, ta, tb)) return out;
    // Samples whose positions t_in + (k + 1/2) h lie before ta or after tb are empty.
    const float first = floorf((ta - t_in) / h - 0.5f) - 1.0f, last = ceilf((tb - t_in) / h - 0.5f) + 1.0f;
    k_begin = first > 0.0f ? static_cast<int>(fminf(first, n_samples)) : 0;
    k_end = last < n_samples - 1.0f ? static_cast<int>(fmaxf(last, 0.0f)) + 1 : K;
  }
  const int omega_large = (k_end - k_begin) / 32;
  const float inv_speed = 1.0f / fmaxf(fabsf(ray.dx), length(ray.wd));  // of (x, r) along the ray, Chebyshev
  const float inv_h = 1.0f / h;
  const float inv_texel = 1.0f / m.texel;
  const Vec3 to_eye = -dir;
  bool previous_empty = false;
  int stride = 2;  // omega_multi's next jump, in samples
  int wait = 0, backoff = 1;  // empty samples to pass before the next attempt
  // The texel a run of samples is in and the transmittance where the ray
  // entered it: every sample in the run is seen through that (the texel plays
  // the voxel's part: P holds the extinction inside it).
  long long run_cell = -1;
  float t_entry[kMaxBands];
  for (int b = 0; b < kMaxBands; ++b) t_entry[b] = 1.0f;
  for (int k = k_begin; k < k_end; ++k) {
    if (visited) ++*visited;
    float chord = h, t = t_in + (float(k) + 0.5f) * h;
    if (k == K - 1) {
      chord = fmaxf(span - float(K - 1) * h, 0.0f);  // never negative, whatever ceil's rounding
      t = t_in + float(K - 1) * h + 0.5f * chord;
    }
    const Vec3 pos = origin + t * dir;
    const Vec3 q = pos - m.origin;
    const float x = dot(q, m.axis);
    const Vec3 w = q - x * m.axis;
    const float r = length(w);
    const float fx = floorf(x * inv_texel), fr = floorf(r * inv_texel);
    const bool outside = !(fx >= 0.0f && fx < float(m.nx) && fr < float(m.nr));  // (or NaN)
    bool empty = outside;
    const int ix = empty ? 0 : static_cast<int>(fx), ir = empty ? 0 : static_cast<int>(fr);
    // The texel the sample reads: (ix, ir), or with a shape deformation (ix,
    // floor(r (1 - d) / l)), the same expression in every mode.
    int ir_read = ir;
    bool pulled = false;
    auto pull = [&]() {
      if (pulled) return;
      pulled = true;
      const float d = shape_pull(deform, ix, w);
      ir_read = static_cast<int>(floorf(r * (1.0f - d) * inv_texel));
    };
    int distance = 0;  // the jump's distance (Distance mode only)
    float reach_slack = 0.0f;  // world units the jump may cover times the speed
    if (!empty && skip == int(AxialSkip::Distance)) {
      if (!shape) {
        distance = m.distance[m.index(ix, ir)];
        empty = distance != 0;
        reach_slack = float(distance - 1) * m.texel - eps;
      } else {
        // Every read radius lies within half = r d_max / 2 of r - half.
        const float half = 0.5f * deform.d_max * r;
        const int ic = static_cast<int>(floorf((r - half) * inv_texel));
        const int d = m.distance[m.index(ix, ic)];
        reach_slack = float(d - 1) * m.texel - eps - half;
        if (d != 0 && reach_slack >= 0.0f) {
          distance = d;
          empty = true;
        } else {
          pull();
          empty = m.distance[m.index(ix, ir_read)] != 0;
        }
      }
    } else if (!empty && skip >= int(AxialSkip::Empty)) {
      const int top = m.height[ix];
      if (shape) {
        const int ir_lo = static_cast<int>(floorf(r * shrink * inv_texel));
        empty = ir_lo >= top || (!kThesis && ir < m.floor[ix]);
        if (!empty) {
          pull();
          empty = ir_read >= top || (!kThesis && ir_read < m.floor[ix]);
        }
      } else {
        empty = ir >= top || (!kThesis && ir < m.floor[ix]);
      }
    }
    if (skip == int(AxialSkip::Naive) || !empty) {
      float tau_v = 0.0f;
      float source[kMaxBands] = {};
      float peak[kMaxBands] = {};  // the diffuse response's forward peak (kDiffuse)
      float lower[kMaxBands];      // colour deformation factors (kDeform)
      for (int b = 0; b < kMaxBands; ++b) lower[b] = 1.0f;
      bool dark = true;
      if (!empty) {
        if (shape) pull();
        const size_t cell = m.index(ix, ir_read);
        tau_v = m.tau_v[cell];
        NEBULA_UNROLL
        for (int b = 0; b < kMaxBands; ++b) {
          if (b >= s.n_bands) break;
          source[b] = m.emission[b] ? m.emission[b][cell] : 0.0f;
          dark = dark && source[b] == 0.0f;
        }
        dark = dark && tau_v == 0.0f;
        if (kStars && tau_v > 0.0f) {
          for (int k_star = 0; k_star < s.n_stars; ++k_star)
            add_star_light(s, s.stars[k_star].position, s.stars[k_star].power, s.stars[k_star].depth_v[cell],
                           chord_irradiance(origin, dir, t - 0.5f * chord, t + 0.5f * chord,
                                            s.stars[k_star].position, s.footprint),
                           tau_v, to_eye, source, &out.table_clamps);
        }
        if constexpr (kDiffuse)
          if (tau_v > 0.0f) add_axial_diffuse_light<kField == AxialField::Zonal>(s, q, x, r, tau_v, to_eye, source, peak);
        if constexpr (kDeform)
          if (deform.colour && !dark) {
            colour_factors(deform, q, s.n_bands, lower);
            NEBULA_UNROLL
            for (int b = 0; b < kMaxBands; ++b) {
              if (b >= s.n_bands) break;
              source[b] *= lower[b];
              peak[b] *= lower[b];
            }
          }
      }
      empty = empty || dark;
      // T_in rule (DESIGN.md section 3), the texel in the voxel's part.
      const long long cell = empty ? -1 : static_cast<long long>(m.index(ix, ir_read));
      if (cell != run_cell) {
        NEBULA_UNROLL
        for (int b = 0; b < kMaxBands; ++b)
          if (b < s.n_bands) t_entry[b] = out.transmittance[b];
      }
      run_cell = cell;
      const float fraction = chord * inv_texel;
      bool visible = false;
      NEBULA_UNROLL
      for (int b = 0; b < kMaxBands; ++b) {
        if (b >= s.n_bands) break;
        out.radiance[b] += t_entry[b] * source[b] * fraction;
        float tau_b = tau_v * s.extinction_ratio[b];
        if constexpr (kDeform) tau_b *= lower[b];
        if constexpr (kDiffuse)
          out.transmittance[b] *= fminf(1.0f, expf(-tau_b * fraction) + peak[b] * fraction);
        else
          out.transmittance[b] *= expf(-tau_b * fraction);
        visible = visible || out.transmittance[b] >= s.min_transmittance;
      }
      if (!visible) break;
    }
    if (empty) run_cell = -1;  // also for samples never shaded: the same runs in every mode
    const bool gap_start = !previous_empty;
    previous_empty = empty;
    if (!empty || skip < int(AxialSkip::Omega)) continue;
    if (kThesis) {
      // The thesis' steps: omega_max from the node the sample lies above,
      // omega_large = omega_max / 32, or omega_max, omega_max / 2, ...,
      // omega_max / 32 in turn; a step is taken when the stretch up to its
      // landing sample is above the height map (max-tree range maximum).
      if (outside) continue;
      const int rest = k_end - 1 - k;
      if (rest < 1) continue;
      const int omega_max =
          axial_detail::thesis_omega_max(m, ray, ix, r * shrink, t, t_in, t_out, inv_h, eps, shrink);
      const int first = skip == int(AxialSkip::ThesisOmegaLarge) ? 5 : 0;
      const int last = skip == int(AxialSkip::ThesisOmegaMulti) ? 5 : first;
      for (int halving = first; halving <= last; ++halving) {
        int n = omega_max >> halving;
        n = n < rest ? n : rest;
        if (n < 1) break;
        if (axial_detail::stretch_is_empty<true, false>(m, ray, t, t + float(n) * h, eps, shrink)) {
          k += n;
          break;
        }
      }
      continue;
    }
    if (skip == int(AxialSkip::Distance)) {
      // Every sample within reach is empty: jump over all of them.
      if (distance == 0) continue;  // outside the map, or not proven for a pulled sample
      const float reach = reach_slack * inv_speed;
      // reach * (1/h) may round up by an ulp of reach: far inside the margin eps.
      const float n = fminf(floorf(reach * inv_h), float(k_end - 1 - k));
      if (n >= 1.0f) k += static_cast<int>(n);
      continue;
    }
    // From an empty sample k: skip samples k+1 .. k+n when the stretch from
    // sample k's position to sample k+n's is empty. After a failed attempt the
    // next ones wait (1, 2, 4, ... up to 32 empty samples), so the hollow
    // parts the maps cannot prove empty cost few queries.
    const int rest = k_end - 1 - k;
    if (rest < 2) continue;
    if (gap_start && (skip == int(AxialSkip::Omega)
                          ? axial_detail::stretch_is_empty<false>(m, ray, t, t + float(rest) * h, eps, shrink)
                          : axial_detail::stretch_is_empty<true>(m, ray, t, t + float(rest) * h, eps, shrink)))
      break;  // omega_max: the rest of the ray, tried once per run of empty samples
    if (wait > 0) {
      --wait;
      continue;
    }
    bool jumped = false;
    if (skip == int(AxialSkip::Omega)) {
      // omega_large = omega_max / 32, the columns' maximum scanned.
      const int n = omega_large < rest ? omega_large : rest;
      if (n >= 2 && axial_detail::stretch_is_empty<false>(m, ray, t, t + float(n) * h, eps, shrink)) {
        k += n;
        jumped = true;
      }
    } else {
      // Hierarchical: one adaptive jump, n doubling after each success and
      // halving after a failure, range extrema from the trees (O(log nx)).
      const int n = stride < rest ? stride : rest;
      if (n >= 2 && axial_detail::stretch_is_empty<true>(m, ray, t, t + float(n) * h, eps, shrink)) {
        k += n;
        stride = 2 * n;
        jumped = true;
      } else {
        stride = n / 2 > 2 ? n / 2 : 2;
      }
    }
    if (jumped) {
      backoff = 1;
    } else {
      wait = backoff;
      backoff = backoff < 32 ? 2 * backoff : 32;
    }
  }
  return out;
}

// The field a scene's march adds (the kernel to run).
NEBULA_HD AxialField axial_field(const AxialMarchScene& s) {
  if (!s.has_diffuse) return AxialField::None;
  return s.diffuse.zonal > 0 ? AxialField::Zonal : AxialField::Harmonics;
}

// Calls f(mode, stars, field, deform) with std::integral_constant /
// std::bool_constant for the run-time mode, whether the scene has stars, its
// diffuse field's kind (only with stars) and whether it has deformations: the
// one place that turns them into template arguments (the CPU loop, the CUDA
// launch).
template <class F>
decltype(auto) dispatch_axial(AxialSkip mode, bool stars, AxialField field, bool deform, F&& f) {
  auto with_deform = [&](auto m, auto st, auto di) -> decltype(auto) {
    if (deform) return f(m, st, di, std::true_type{});
    return f(m, st, di, std::false_type{});
  };
  using None = std::integral_constant<AxialField, AxialField::None>;
  auto with_stars = [&](auto m) -> decltype(auto) {
    if (!stars) return with_deform(m, std::false_type{}, None{});
    if (field == AxialField::Zonal)
      return with_deform(m, std::true_type{}, std::integral_constant<AxialField, AxialField::Zonal>{});
    if (field == AxialField::Harmonics)
      return with_deform(m, std::true_type{}, std::integral_constant<AxialField, AxialField::Harmonics>{});
    return with_deform(m, std::true_type{}, None{});
  };
  switch (mode) {
    case AxialSkip::Naive: return with_stars(std::integral_constant<AxialSkip, AxialSkip::Naive>{});
    case AxialSkip::Empty: return with_stars(std::integral_constant<AxialSkip, AxialSkip::Empty>{});
    case AxialSkip::GlobalMax: return with_stars(std::integral_constant<AxialSkip, AxialSkip::GlobalMax>{});
    case AxialSkip::Omega: return with_stars(std::integral_constant<AxialSkip, AxialSkip::Omega>{});
    case AxialSkip::OmegaMulti: return with_stars(std::integral_constant<AxialSkip, AxialSkip::OmegaMulti>{});
    case AxialSkip::ThesisOmegaMax:
      return with_stars(std::integral_constant<AxialSkip, AxialSkip::ThesisOmegaMax>{});
    case AxialSkip::ThesisOmegaLarge:
      return with_stars(std::integral_constant<AxialSkip, AxialSkip::ThesisOmegaLarge>{});
    case AxialSkip::ThesisOmegaMulti:
      return with_stars(std::integral_constant<AxialSkip, AxialSkip::ThesisOmegaMulti>{});
    case AxialSkip::Distance: break;
  }
  return with_stars(std::integral_constant<AxialSkip, AxialSkip::Distance>{});
}

}  // namespace nebula
