// The dense inner work of one EM iteration over a block of points (private).
//
// em_kernel.cpp is compiled once per instruction set (SSE2 baseline, AVX2,
// AVX-512) into separate namespaces; em_block() picks the best one the CPU
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
/// U11 U12 U13 U22 U23 U33), log(weight) + log det U - 2 log(2 pi) (1), pad (1).
inline constexpr int kParamStride = 16;
/// Doubles per component in the sufficient statistics, all centred at the
/// component's current mean: sum r (1), sum r d (4), upper triangle of
/// sum r d d^T (10, same order as U).
inline constexpr int kStatStride = 15;

/// One block: `count` <= kBlock points given as four coordinate arrays.
/// Computes each point's log-density under the `n_active` components listed in
/// `active` (indices into `params`; all M for the exact E-step), the point's
/// log-sum-exp, the responsibilities, and adds the block's statistics
/// (accumulated in float within the block, then in double) into `stats`
/// (M x kStatStride, indexed by component). `scratch` holds
/// (kBlock + 1) x n_active floats. Returns the sum of the points'
/// log-likelihoods.
using EmBlockFn = double (*)(const float* const xyzg[4], int count, const float* params,
                             const std::uint32_t* active, std::size_t n_active, float* scratch, double* stats);

/// The kernel for this CPU (resolved once).
EmBlockFn em_block_kernel();
/// Name of the instruction set the kernel uses ("avx512", "avx2", "sse2").
const char* em_kernel_isa();

}  // namespace sogmm::detail
