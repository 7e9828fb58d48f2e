// Errors raised by the SOGMM C++ core.
//
// Every function of the core reports bad input by throwing sogmm::Error with a
// code (so the C API can map it to a status without parsing text) and a
// message naming the problem. Nothing in the core aborts the process.
#pragma once

#include <stdexcept>
#include <string>

namespace sogmm {

/// Why an operation failed. Values are stable: the C API maps them 1:1.
enum class ErrorCode {
  InvalidArgument = 1,  ///< a parameter is out of range (bandwidth <= 0, K < 1, ...)
  InvalidData = 2,      ///< input data unusable (empty cloud, NaN, size mismatch)
  Numeric = 3,          ///< a numerical failure (non-SPD covariance, NaN result)
  Io = 4,               ///< a file could not be read or written
  Format = 5,           ///< a file or buffer is not a valid .sogmm / JSON document
  Limit = 6,            ///< input exceeds a documented resource limit
  Cancelled = 7,        ///< a progress sink asked to stop (sogmm/progress.hpp)
};

/// Exception carrying an ErrorCode and a human-readable, one-line message.
class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  /// The category of the failure.
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

/// Throws Error(code, message) when `condition` is false.
inline void require(bool condition, ErrorCode code, const std::string& message) {
  if (!condition) throw Error(code, message);
}
/// The same for a literal message, which then costs no allocation unless it
/// is thrown (checks inside loops over every input value use this one).
inline void require(bool condition, ErrorCode code, const char* message) {
  if (!condition) throw Error(code, message);
}

}  // namespace sogmm
