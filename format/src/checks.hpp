// Value checks every reader applies and every writer enforces
// (spec/format.md section 9, step 19 and step 11b).
#pragma once

#include <array>

#include "sogmm/gmm.hpp"

namespace sogmm::format::detail {

/// Tolerances of the value checks (normative, spec/format.md section 9).
inline constexpr double kWeightSumTolerance = 1e-4;
inline constexpr double kSymmetryTolerance = 1e-5;

/// Step 19 on the float32 values of a model whose array lengths agree with
/// M >= 1 (covariances full, 16 per component): runs the checks in the
/// normative order and throws FormatError with reason non_finite,
/// bad_weights, not_symmetric or not_spd (ErrorCode::Numeric). The values of
/// an F64 file are checked after rounding to float32, as the model holds them,
/// and the model must also pass sogmm::validate (what every C API handle
/// keeps), so that every entry point gives a file one verdict.
void check_values(const Gmm& gmm);

/// Throws FormatError("bad_pose", InvalidData) unless sogmm::rigid_pose_error
/// accepts the pose: finite, last row (0, 0, 0, 1) and a rotation block R with
/// |R^T R - I| <= sogmm::kPoseTolerance (1e-3) entrywise and det(R) > 0.
void check_pose(const std::array<double, 16>& pose);

}  // namespace sogmm::format::detail
