// A vectorizable float exp (private to the core).
#pragma once

#include <cmath>
#include <cstdint>

namespace sogmm::detail {

/// exp(x) for x <= 0 with relative error < 1e-7 on [-87, 0] and exactly 0
/// below -87 (where float exp would be denormal). Written with plain
/// arithmetic and a bit cast so that compilers vectorize loops calling it
/// (std::exp would be a library call per element). Cephes-style: x = n ln2 + r,
/// |r| <= ln2 / 2, exp(r) by a degree-6 polynomial, 2^n built in the exponent.
inline float fast_exp(float x) {
  // Clamped to [-87, 88] (ternaries, not fmin/fmax, which may become libm
  // calls): the integer conversion of n below is then always defined (NaN
  // maps to -87), and callers' x <= 0 is unchanged.
  float xc = x > -87.0f ? x : -87.0f;
  xc = xc < 88.0f ? xc : 88.0f;
  // Round to nearest with the 1.5 * 2^23 trick (no library call).
  const float n = (xc * 1.44269504088896341f + 12582912.0f) - 12582912.0f;
  float r = xc - n * 0.693359375f;
  r = r - n * -2.12194440e-4f;
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  const std::int32_t bits = (static_cast<std::int32_t>(n) + 127) << 23;
  const float result = p * __builtin_bit_cast(float, bits);
  return x < -87.0f ? 0.0f : result;
}

}  // namespace sogmm::detail
