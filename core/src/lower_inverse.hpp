// The inverse of a 4 x 4 lower-triangular matrix (private), bit for bit as
// Eigen's `l.triangularView<Eigen::Lower>().solve(Identity)`.
//
// Why: EM packs every component on every pass (U = L^-T, em.cpp's
// pack_component), serially between the parallel E-steps. For a fixed 4 x 4
// right-hand side Eigen still takes its general blocked solver
// (triangular_solve_matrix, with gemm packing), which was 2-3% of a
// truncated d = 5 fit's CPU time, all of it serial. This is that solver's
// arithmetic for one 4-row panel, without the blocking: per pivot row i the
// reciprocal r = 1 / L_ii, each column's entry scaled by r, then subtracted
// (times L_ki) from the rows below, column by column. The same operations in
// the same order give the same bits (no fused multiply-add: the core's
// generic code is compiled for the baseline ISA, as Eigen's solver is), so
// a fit packs exactly the parameters it packed before
// (test LowerInverse.MatchesEigensSolveBitForBit).
#pragma once

#include <Eigen/Core>

namespace sogmm::detail {

/// X with L X = I for a lower-triangular L whose diagonal is nonzero (only
/// the lower triangle of `l` is read); X is lower-triangular.
inline Eigen::Matrix4d lower_inverse(const Eigen::Matrix4d& l) {
  Eigen::Matrix4d x = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 4; ++i) {
    const double r = 1.0 / l(i, i);
    for (int j = 0; j < 4; ++j) {
      const double b = (x(i, j) *= r);
      for (int k = i + 1; k < 4; ++k) x(k, j) -= b * l(k, i);
    }
  }
  return x;
}

}  // namespace sogmm::detail
