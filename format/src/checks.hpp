// Value checks every reader applies and every writer enforces
// (spec/format.md section 9, step 19 and step 11b).
#pragma once

#include <array>

#include "sogmm/error.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format::detail {

/// Tolerances of the value checks (normative, spec/format.md section 9).
inline constexpr double kWeightSumTolerance = 1e-4;
inline constexpr double kSymmetryTolerance = 1e-5;

/// Step 19 on the float32 values of a model whose array lengths agree with
/// M >= 1 (covariances full, 16 per component): runs the checks in the
/// normative order (the symmetry test on the stored matrix, the Cholesky
/// test on its symmetric part) and throws FormatError with reason non_finite,
/// bad_weights, not_symmetric or not_spd (ErrorCode::Numeric). The values of
/// an F64 file are checked after rounding to float32, as the model holds them,
/// and the model must also pass sogmm::validate (what every C API handle
/// keeps), so that every entry point gives a file one verdict.
/// `delta`: the explicit components of a map delta (spec/format.md section
/// 2.5), whose weights need not sum to 1 (and M may be 0): the sum test and
/// sogmm::validate (which holds it too) are left out.
void check_values(const Gmm& gmm, bool delta = false);

/// Replaces every covariance of a model that passed check_values by its
/// symmetric part (spec/format.md section 5.1: a reader returns symmetric
/// matrices), then holds it to sogmm::validate (not_spd) again.
void symmetrize(Gmm& gmm);

/// Throws FormatError(code, "bad_metadata") naming the first double of the
/// fit record or the camera that is NaN or infinite (spec/format.md section
/// 4.2: they are finite, so that the JSON dump can hold them).
void check_metadata_numbers(const Model& model, ErrorCode code);

/// Throws FormatError("bad_pose", InvalidData) unless sogmm::rigid_pose_error
/// accepts the pose: finite, last row (0, 0, 0, 1) and a rotation block R with
/// |R^T R - I| <= sogmm::kPoseTolerance (1e-3) entrywise and det(R) > 0.
void check_pose(const std::array<double, 16>& pose);

}  // namespace sogmm::format::detail
