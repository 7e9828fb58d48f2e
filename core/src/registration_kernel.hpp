// The per-pair scoring of a point-to-model registration (private;
// registration.cpp), compiled once per instruction set
// (registration_kernel.cpp, like occupancy_kernel.cpp) and chosen with the
// EM kernels' instruction set.
//
// Why a kernel: scoring one (point, candidate component) pair is two dozen
// multiply-adds on values of one component, and a 12k-point frame has
// ~7 10^4 such pairs per evaluation (5.7 a point on the loop frames against
// the loop map). Laid out as arrays over the pairs of a block of points
// (the candidates whose box holds the point, listed by registration.cpp),
// the loop runs at the machine's vector width: component values gathered
// from one record per component, the point's copied beside each pair. The
// terms exp(lp - top) of the responsibilities are a second vector pass.
//
// The values are the scalar formulas' (the model source's pair_log_density
// without a source covariance) but not bitwise: the AVX2 / AVX-512 builds
// contract multiply-adds into fused ones, and the precision is the mean of
// its two triangles. Which pairs are scored does not depend on the kernel.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sogmm::detail {

/// Doubles per component record of a registration level (the fields below:
/// two 64-byte lines).
inline constexpr int kPairRecord = 16;
/// A component record's fields (offsets into its kPairRecord doubles): the
/// spatial mean, the upper triangle of the (conditional) spatial precision
/// P, the gray gain (conditional mean slope Sigma_xg / s_gg; 0 without
/// gray), the gray mean, 1 / s_gg (0 without gray), the log-density's
/// constant log((1 - eps) pi) - log det(2 pi Sigma) / 2, and the gray
/// marginal's constant -(log(2 pi) + log s_gg) / 2 (0 without gray).
enum PairField : int {
  kMuX, kMuY, kMuZ,
  kP00, kP01, kP02, kP11, kP12, kP22,
  kGainX, kGainY, kGainZ,
  kMuGray, kInvSgg, kLogNorm, kLogNormGray,
};

/// The pairs of a block: inputs (candidate id, the point at the current
/// pose and its gray, and optionally the point's depth-noise axis u) and
/// outputs per pair.
///
/// With u (ux non-null): the point's own noise u u^T is added to the
/// component's (conditional) spatial covariance S, as the source component's
/// is in D2D, so the pair's precision is the rank-one update (Sherman-
/// Morrison) P' = (S + u u^T)^-1 = P - shrink (P u)(P u)^T with shrink =
/// 1 / (1 + u^T P u), and log det grows by log(1 + u^T P u) (fast_log.hpp).
/// The outputs are then P' r, r^T P' r and the log-density under S + u u^T;
/// P u and shrink give P' to the caller. u = 0 gives exactly the values
/// without u.
struct RegistrationPairs {
  const std::uint32_t* id;
  const double *x, *y, *z, *gray;
  const double *ux, *uy, *uz;   ///< the depth-noise axis (null: no noise; then pu and shrink are not written)
  double* log_density;
  double *pr_x, *pr_y, *pr_z;   ///< P r with r the (gray-conditioned) residual x - mu - gain (gray - mu_gray)
  double* quad;                 ///< r^T P r
  double *pu_x, *pu_y, *pu_z;   ///< with u: P u (P before the update)
  double* shrink;               ///< with u: 1 / (1 + u^T P u)
};

/// Scores pairs 0..count-1 against `records` (kPairRecord doubles per
/// component).
using RegistrationPairsFn = void (*)(const double* records, const RegistrationPairs& pairs, std::size_t count);

/// Sets term[j] = exp(log_density[j] - top[j]) for j < count (term may be
/// log_density), where log_density[j] <= top[j] (the largest log-density of
/// the pair's point): fast_exp_double (fast_exp.hpp), within 5e-16 relative
/// of exp and 0 below -708, where a term cannot change a sum whose largest
/// term is exp(0) = 1.
using RegistrationTermsFn = void (*)(const double* log_density, const double* top, double* term, std::size_t count);

/// The kernels for this CPU (the instruction set em_kernels() chose).
struct RegistrationKernels {
  RegistrationPairsFn pairs;
  RegistrationTermsFn terms;
};
const RegistrationKernels& registration_kernels();

}  // namespace sogmm::detail
