// The dense inner work of one EM iteration over a block of points (private).
//
// em_kernel.cpp is compiled once per instruction set (SSE2 baseline, AVX2,
// AVX-512) into separate namespaces; em_kernels() picks the best one the CPU
// supports at run time, so the portable build never executes an instruction
// the machine lacks (no SIGILL) yet uses wide vectors where present.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sogmm::detail {

/// Points per block: the scratch of a block is kBlock x M floats. 256 points
/// amortise the per-component work (broadcasts, horizontal sums) over 16
/// AVX-512 vectors while keeping float partial sums short.
inline constexpr int kBlock = 256;
/// Floats per component in the packed parameter array: mean (4), upper
/// triangle of the precision Cholesky factor U (10, row-major: U00 U01 U02 U03
/// U11 U12 U13 U22 U23 U33), log(weight) + log det U - 2 log(2 pi) (1), and a
/// flag (1): 0 = evaluate in float32; 1 = the component is too elongated for
/// float32 (see em.cpp, needs_double), so the kernels evaluate it and
/// accumulate its statistics in double from the same layout in double
/// (`exact`, kParamStride doubles per component).
inline constexpr int kParamStride = 16;
/// Doubles per component in the sufficient statistics, all centred at the
/// component's current mean: sum r (1), sum r d (4), upper triangle of
/// sum r d d^T (10, same order as U).
inline constexpr int kStatStride = 15;

/// A block of `count` <= kBlock points as four coordinate arrays.
struct Block {
  const float* xyzg[4];
  int count;
};

/// Log-density of the block's points under the `n` components listed in
/// `components` (indices into `params`): row i of `rows` (kBlock floats each)
/// receives component components[i] and `row_lp_max[i]` its largest value;
/// `max_lp` (kBlock floats) is raised to the running maximum per point. Rows
/// for more components can be appended by further calls before em_finish.
/// `exact` holds the double parameters of the flagged components (may be null
/// when none is flagged).
using EmLogDensityFn = void (*)(const Block& block, const float* params, const double* exact,
                                const std::uint32_t* components, std::size_t n, float* rows, float* row_lp_max,
                                float* max_lp);

/// Turns the `n` rows of log-densities into responsibilities (log-sum-exp per
/// point over the rows) and adds the block's sufficient statistics
/// (accumulated in float within the block, then in double; in double
/// throughout for flagged components, centred at their double mean) into
/// `stats` (M x kStatStride, indexed by component). A row whose largest log-density
/// is more than 87 below every point's maximum has responsibilities exactly 0
/// in float and is skipped without changing the result. With a finite
/// `nats` (the truncated E-step's), a row's exponentials and statistics run
/// only over the aligned segments of kSegment points from its first to its
/// last point whose log-density is within `nats` of that point's maximum:
/// every term left out (of the normalisers and the statistics) is more than
/// `nats` below its point's best (the truncation's guarantee), and a row with
/// no such point is skipped. Infinite `nats`: every point (exact). On return
/// `row_lp_max[i]` holds the largest exp(lp - max) of row i over its range
/// (0 for skipped rows). Returns the sum of the points' log-likelihoods
/// (from 16 products of the points' sums, one log each); with `squares`
/// non-null, from each point's own log instead, and adds the sum of their
/// squares to `*squares` (the spread of the per-point log-likelihoods, for
/// EmOptions::tol_standard_errors; 16 times the logs, so only when asked).
using EmFinishFn = double (*)(const Block& block, const float* params, const double* exact,
                              const std::uint32_t* components, std::size_t n, float* rows, const float* max_lp,
                              float* row_lp_max, double* stats, float nats, double* squares);

/// Points per segment of a row's statistics range (see EmFinishFn): one
/// AVX-512 vector, so the range starts aligned on every instruction set and
/// the terms left out do not depend on the vector width.
inline constexpr int kSegment = 16;

/// The truncated E-step's upper bounds (em_truncation.cpp) of the `m`
/// components in `col` (BoundParams' 15 columns of m doubles) over the box
/// `box` (min[4], max[4]) into `upper` (m doubles); the same doubles on
/// every instruction set.
using EmUpperBoundsFn = void (*)(const double* col, std::size_t m, const float* box, double* upper);

/// The kernels for this CPU (resolved once).
struct EmKernels {
  EmLogDensityFn log_density;
  EmFinishFn finish;
  EmUpperBoundsFn upper_bounds;
  const char* isa;  ///< "avx512", "avx2" or "sse2"
};
const EmKernels& em_kernels();

}  // namespace sogmm::detail
