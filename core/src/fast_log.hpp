// A vectorizable double log for arguments >= 1 (private to the core).
#pragma once

#include <cstdint>

namespace sogmm::detail {

// static, as fast_exp.hpp's functions: each per-ISA object keeps its own copy.

/// log(x) for finite x >= 1, within 1e-15 relative of std::log (exactly 0 at
/// x = 1). Written with plain arithmetic and bit casts so that loops calling
/// it vectorize (std::log would be a library call per element): x = 2^e m with
/// m in [sqrt(1/2), sqrt(2)), log m = 2 atanh(s) with s = (m - 1) / (m + 1),
/// |s| <= 0.1716, by its odd series up to s^19 / 19 (the first term left out,
/// 2 s^21 / 21, is below 3e-17 of 2 s), and e ln 2 with ln 2 split so that
/// e ln2_hi is exact. The exponent becomes a double by the 2^52 trick (no
/// 64-bit integer conversion, which AVX2 lacks).
static inline double fast_log_ge1(double x) {
  constexpr std::uint64_t kMantissa = 0x000FFFFFFFFFFFFFull;
  constexpr std::uint64_t kOne = 0x3FF0000000000000ull;         // the bits of 1.0
  constexpr std::uint64_t kTwoPow52 = 0x4330000000000000ull;    // the bits of 2^52
  const std::uint64_t bits = __builtin_bit_cast(std::uint64_t, x);
  // x >= 1: the sign bit is 0, so the shift leaves the biased exponent.
  const double biased = __builtin_bit_cast(double, (bits >> 52) | kTwoPow52) - 4503599627370496.0;
  double m = __builtin_bit_cast(double, (bits & kMantissa) | kOne);  // in [1, 2)
  const bool high = m > 1.4142135623730951;
  m = high ? 0.5 * m : m;
  const double e = (biased - 1023.0) + (high ? 1.0 : 0.0);
  const double s = (m - 1.0) / (m + 1.0);
  const double s2 = s * s;
  double p = 1.0 / 19;
  p = p * s2 + 1.0 / 17;
  p = p * s2 + 1.0 / 15;
  p = p * s2 + 1.0 / 13;
  p = p * s2 + 1.0 / 11;
  p = p * s2 + 1.0 / 9;
  p = p * s2 + 1.0 / 7;
  p = p * s2 + 1.0 / 5;
  p = p * s2 + 1.0 / 3;
  const double log_m = 2.0 * s + 2.0 * s * s2 * p;
  return e * 6.93147180369123816490e-1 + (e * 1.90821492927058770002e-10 + log_m);
}

}  // namespace sogmm::detail
