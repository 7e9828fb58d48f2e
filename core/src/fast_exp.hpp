// A vectorizable float exp (private to the core).
#pragma once

#include <cmath>
#include <cstdint>

namespace sogmm::detail {

// static: each object (the per-ISA kernels and the baseline code) keeps its
// own copy, so a copy the compiler does not inline (e.g. at -O0) is never
// merged across objects by the linker, which could hand an SSE2 caller the
// AVX-512 object's instructions.

/// exp(x) for x <= 0 with relative error < 1e-7 on [-87, 0] and exactly 0
/// below -87 (where float exp would be denormal). Written with plain
/// arithmetic and a bit cast so that compilers vectorize loops calling it
/// (std::exp would be a library call per element). Cephes-style: x = n ln2 + r,
/// |r| <= ln2 / 2, exp(r) by a degree-6 polynomial, 2^n built in the exponent.
static inline float fast_exp(float x) {
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

/// exp(x) in double for x <= 0, relative error below 5e-16 on [-708, 0] and
/// exactly 0 below -708 (where exp would be denormal: a term that small
/// cannot change a sum of terms of which the largest is 1). Vectorizable for
/// the same reasons as fast_exp: x = n ln2 + r with |r| <= ln2 / 2, exp(r) by
/// its Taylor polynomial of degree 12 (truncation error r^13 / 13! < 2e-16;
/// FMAs only, no division, which is slow in vector units), n rounded by the
/// 1.5 * 2^52 trick whose low mantissa bits then hold n as an integer, so 2^n
/// is built with 64-bit integer adds and shifts (no float-to-integer
/// conversion, which AVX2 lacks for 64-bit lanes).
static inline double fast_exp_double(double x) {
  constexpr double kShift = 6755399441055744.0;  // 1.5 * 2^52
  const double xc = x > -708.0 ? x : -708.0;     // also NaN -> -708
  const double t = xc * 1.4426950408889634074 + kShift;
  const double n = t - kShift;
  // ln2 split in a high part with few bits (n * hi is exact) and the rest.
  double r = xc - n * 6.93147180369123816490e-1;
  r = r - n * 1.90821492927058770002e-10;
  double p = 1.0 / 479001600.0;  // 1 / 12!
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  const std::int64_t k = __builtin_bit_cast(std::int64_t, t) - __builtin_bit_cast(std::int64_t, kShift);
  const double scale = __builtin_bit_cast(double, (k + 1023) << 52);
  return x < -708.0 ? 0.0 : p * scale;
}

}  // namespace sogmm::detail
