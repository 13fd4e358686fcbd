#pragma once
// How the field's response is tapered (docs/diffuse.md, "Truncation"): the
// delta-M sum as it is, or its degrees 1..N times Lanczos's sigma factors.
// Its own header: scenes name it.
#include <string>

namespace nebula {

enum class DiffuseTaper : int {
  Auto = 0,     // Lanczos where the field has zonal degrees (strongly forward dust: g >= 0.8 by default), else none
  None = 1,     // p_l - peak as they are
  Lanczos = 2   // sigma_l (p_l - peak), on the harmonics' and the zonal response (everywhere before 2026-11-29)
};

inline const char* to_string(DiffuseTaper t) {
  return t == DiffuseTaper::Lanczos ? "lanczos" : t == DiffuseTaper::None ? "none" : "auto";
}

// false for a name that is none of them (the caller names the key).
inline bool parse_diffuse_taper(const std::string& name, DiffuseTaper& out) {
  for (DiffuseTaper t : {DiffuseTaper::Auto, DiffuseTaper::None, DiffuseTaper::Lanczos})
    if (name == to_string(t)) {
      out = t;
      return true;
    }
  return false;
}

// The taper a field uses: auto resolved by whether it has zonal degrees
// (zonal > degree). There the harmonics stop at degree 3 while most of a
// g >= 0.8 phase function lies beyond them, and the untapered series rings:
// on a slab behind its star at g = 0.9 it made the dust 20-30% too bright away
// from the star and 13-25% too dark next to it. Below, the untapered series is
// the better one: the taper moved light from the dust seen in the field's
// direction to the dust lit from the side (docs/diffuse.md, "Truncation").
inline DiffuseTaper resolved_taper(DiffuseTaper t, int degree, int zonal) {
  if (t != DiffuseTaper::Auto) return t;
  return zonal > degree ? DiffuseTaper::Lanczos : DiffuseTaper::None;
}

}  // namespace nebula
