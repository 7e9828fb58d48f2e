// Value checks every reader applies and every writer enforces
// (spec/format.md section 9, steps 15-18).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace sogmm::format::detail {

/// Tolerances of the value checks (normative, spec/format.md section 9).
inline constexpr double kWeightSumTolerance = 1e-4;
inline constexpr double kSymmetryTolerance = 1e-5;

/// Model arrays widened to double. `cov` holds 10 values per component when
/// `packed`, else 16 (row-major).
struct ArraysView {
  std::uint64_t m = 0;
  const std::vector<double>* weights = nullptr;
  const std::vector<double>* means = nullptr;
  const std::vector<double>* cov = nullptr;
  bool packed = true;
};

/// Runs the value checks in the normative order; throws FormatError with
/// reason non_finite, bad_weights, not_symmetric or not_spd (ErrorCode::Numeric).
void check_values(const ArraysView& a);

/// Throws FormatError("bad_pose", InvalidData) unless sogmm::rigid_pose_error
/// accepts the pose: finite, last row (0, 0, 0, 1) and a rotation block R with
/// |R^T R - I| <= sogmm::kPoseTolerance (1e-3) entrywise and det(R) > 0.
void check_pose(const std::array<double, 16>& pose);

/// Full symmetric 4x4 from the 10 upper-triangle values (row by row).
void unpack_upper(const double* packed, double* full);

}  // namespace sogmm::format::detail
