// The one check that query input is finite, shared by the queries
// (query.cpp) and their chunked progress runs (query_progress.cpp), so that
// both name the offending row the same way. Never installed.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {

/// Throws Error(InvalidData) naming the first row of `rows` x `width` floats
/// at `v` that holds NaN or Inf; `what` names the input ("points to score").
inline void require_finite_rows(const float* v, std::size_t rows, std::size_t width, const char* what) {
  const std::size_t count = checked::mul<std::size_t>(rows, width, "input size");
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(v[i]))
      throw Error(ErrorCode::InvalidData,
                  std::string(what) + " has a non-finite value (NaN or Inf) at row " + std::to_string(i / width));
}

}  // namespace sogmm::detail
