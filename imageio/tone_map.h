#pragma once
// The display transform of PNG output, shared with anything that shows an
// image on screen so both agree: linear value × exposure, clamped to [0, 1],
// then the sRGB transfer curve of IEC 61966-2-1, then 8 bits.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/display.h"

namespace nebula {

// IEC 61966-2-1 encoding of a linear value in [0, 1]: a straight line near
// black (no infinite slope at 0), a 1/2.4 power above.
inline double srgb_encode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// The 8-bit level of a linear pixel value: round to nearest of 255 × encoded.
// A NaN shows as black rather than as whatever lround makes of it.
inline uint8_t srgb_level(float value, double exposure) {
  const double x = double(value) * exposure;
  const double scaled = x > 0.0 ? std::min(x, 1.0) : 0.0;
  return static_cast<uint8_t>(std::lround(255.0 * srgb_encode(scaled)));
}

// The 8-bit level of a pixel under a display transform (core/display.h):
// stretch_value of value x exposure, then the sRGB curve. The default
// (linear, white 1) is srgb_level exactly.
inline uint8_t display_level(float value, double exposure, const DisplaySettings& display) {
  return static_cast<uint8_t>(std::lround(255.0 * srgb_encode(stretch_value(double(value) * exposure, display))));
}

}  // namespace nebula
