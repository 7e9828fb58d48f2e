// Components rounded to the precision they need (MapOptions::
// component_precision; issue 33), so that the low mantissa bits a fit leaves
// in every float are zero and a delta's byte-stream-split arrays compress
// them away. Never installed.
#pragma once

#include "sogmm/gmm.hpp"
#include "sogmm/map.hpp"

namespace sogmm::detail {

/// `gmm` with each component's mean and covariance rounded to nearest on
/// power-of-two grids chosen from the component itself, so that in its own
/// metric (L the Cholesky factor of its covariance S, lambda its smallest
/// eigenvalue) the rounding moves it by at most `precision`:
/// - mean: grid q_m, the largest power of two <= precision / sqrt(t), with
///   t = trace(S^-1) >= 1 / lambda: the error d has |d_i| <= q_m / 2, so
///   |L^-1 d| <= |d| / sqrt(lambda) <= q_m sqrt(t) <= precision (in standard
///   deviations);
/// - covariance: grid q_c, the largest power of two <= precision / (2 t): the
///   error E has |E_ij| <= q_c / 2, ||E||_2 <= ||E||_F <= 2 q_c, so every
///   eigenvalue of L^-1 (S + E) L^-T is within 1 +- precision (< 1: still
///   positive definite, and symmetric entries round alike).
/// Rounding to a grid is exact in float32 (ldexp and nearbyint, no other
/// arithmetic) and t comes from stored_cholesky (binary64, no fused
/// multiply-add, one summation order), so every CPU rounds to the same bits.
/// A component whose rounded covariance fails stored_cholesky (float32
/// corner cases the bound does not see) keeps its values. Weights are not
/// touched (a flush rescales them anyway). precision 0 returns `gmm`.
Gmm round_to_precision(const Gmm& gmm, double precision);

/// Grid of a frame's recorded pose under a component precision > 0: 2^-16
/// (1.5e-5; rotation entries unitless, translations in metres).
inline constexpr int kPoseGridLog2 = -16;

/// The pose a map records for a frame (FrameStats::pose, the `map_frames`
/// line a file and a delta carry): `pose` itself when precision is 0, else
/// its first three rows rounded to nearest (ties to even) on the grid 2^-16,
/// so that the binary frame record of a map file (spec/format.md 2.3.2)
/// compresses 2.3x better (its low mantissa bytes are zero). The rounding
/// moves each entry by at most 2^-17, so a point p of the camera frame moves
/// by at most 3 * 2^-17 * |p| + sqrt(3) * 2^-17 (0.08 mm at 3 m), far below
/// the precision * sigma the components already moved, and R^T R stays within
/// 5e-5 of the identity (the rigid test allows 1e-3). It happens before the
/// frame is recorded, so a map and the map loaded from its file hold the same
/// bits and answer alike. Exact (ldexp and nearbyint only), so every CPU
/// rounds alike. Only the record is rounded: the fit uses the given pose.
Pose recorded_pose(const Pose& pose, double precision);

}  // namespace sogmm::detail
