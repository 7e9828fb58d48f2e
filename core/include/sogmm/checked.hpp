// Checked arithmetic: the one place where core, format and capi turn a double
// into an integer or compute a size that could overflow.
//
// Why: a static_cast from a double outside the integer's range is undefined
// behaviour (UBSan float-cast-overflow), and size products wrap silently. Both
// turned hostile inputs into crashes or misleading errors. Every such
// conversion goes through these helpers, which either give the exact result or
// throw sogmm::Error(Limit) naming what was being computed.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>

#include "sogmm/error.hpp"

namespace sogmm::checked {

/// Formats a double so that it reads back to the same value (17 significant
/// digits), for error messages that must show the offending value.
inline std::string exact(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

/// Converts `v` to Int by truncation toward zero (as static_cast would) when
/// `v` is finite and the result fits Int; otherwise returns false.
template <typename Int>
bool try_to_int(double v, Int* out) {
  static_assert(std::is_integral_v<Int>, "Int must be an integer type");
  if (!std::isfinite(v)) return false;
  const double t = std::trunc(v);
  // 2^digits is exact in double; the largest Int is 2^digits - 1.
  const double upper = std::ldexp(1.0, std::numeric_limits<Int>::digits);
  const double lower = std::is_signed_v<Int> ? -upper : 0.0;
  if (!(t >= lower && t < upper)) return false;
  *out = static_cast<Int>(t);
  return true;
}

/// As try_to_int, but throws Error(Limit) "WHAT (V) does not fit ..." on failure.
template <typename Int>
Int to_int(double v, const char* what) {
  Int out{};
  // The message is built only on failure: these run once per point in the
  // fit's hot loops (cell indices), where formatting a double each time cost
  // 6% of a d = 1 fit.
  if (!try_to_int(v, &out))
    throw Error(ErrorCode::Limit, std::string(what) + " (" + exact(v) + ") is not a finite value in the integer range");
  return out;
}

/// floor(v) as Int, checked (grid and bin indices).
template <typename Int>
Int floor_to_int(double v, const char* what) {
  return to_int<Int>(std::floor(v), what);
}

/// a * b, or false when it overflows.
template <typename Int>
bool try_mul(Int a, Int b, Int* out) {
  return !__builtin_mul_overflow(a, b, out);
}

/// a + b, or false when it overflows.
template <typename Int>
bool try_add(Int a, Int b, Int* out) {
  return !__builtin_add_overflow(a, b, out);
}

/// a * b, throwing Error(Limit) naming `what` when it overflows.
template <typename Int>
Int mul(Int a, Int b, const char* what) {
  Int out{};
  if (!try_mul(a, b, &out))  // message only on failure, as to_int
    throw Error(ErrorCode::Limit, std::string(what) + " overflows (" + std::to_string(a) + " x " + std::to_string(b) + ")");
  return out;
}

/// a + b, throwing Error(Limit) naming `what` when it overflows.
template <typename Int>
Int add(Int a, Int b, const char* what) {
  Int out{};
  if (!try_add(a, b, &out))  // message only on failure, as to_int
    throw Error(ErrorCode::Limit, std::string(what) + " overflows (" + std::to_string(a) + " + " + std::to_string(b) + ")");
  return out;
}

/// Bytes of `count` elements of `elem_size` bytes, checked.
inline std::size_t bytes(std::size_t count, std::size_t elem_size, const char* what) {
  return mul<std::size_t>(count, elem_size, what);
}

}  // namespace sogmm::checked
