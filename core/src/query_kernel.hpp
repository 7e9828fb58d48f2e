// The dense inner work of score_samples and regress_gray over a block of
// points (private), in double.
//
// Like the EM kernels (em_kernel.hpp), query_kernel.cpp is compiled once per
// instruction set and query_kernels() picks the one em_kernels() chose, so
// the loops run over the points of a block, with one component's parameters
// broadcast, at the machine's vector width. Unlike the EM they work in
// double, as score_samples and regress_gray are documented to.
//
// Every kernel call adds the terms of `n` more components to a running
// per-point state (an online log-sum-exp, rescaled when a point's maximum
// rises), so a caller can evaluate all components at once (the exact
// queries) or a few first and more once it knows each point's best term (the
// culled queries). Components are taken kQueryChunk at a time, so the scratch
// stays small whatever the model's size. Results depend only on the list of
// components and its order, never on the thread that runs the block.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

namespace sogmm::detail {

/// Points per block (8 AVX-512 or 16 AVX2 vectors of doubles).
inline constexpr int kQueryBlock = 64;
/// Components per chunk of the online log-sum-exp: scratch of 2 x 128 x 64
/// doubles (128 KiB) per thread.
inline constexpr std::size_t kQueryChunk = 128;
/// Doubles of scratch a kernel call needs.
inline constexpr std::size_t kQueryScratch = 2 * kQueryChunk * kQueryBlock;
/// Doubles per component in a packed parameter array. Layout for 3-D (the
/// spatial marginal, score dims 3 and regress): mean (3), L^-1 of the xyz
/// covariance, lower triangle row by row (6), log w - log det L - 3/2 log 2 pi
/// (1), regression gain Sigma_gx Sigma_xx^-1 (3), mean gray (1), conditional
/// gray variance (1), pad (1). For 4-D (score dims 4): mean (4), L^-1 lower
/// (10), log w - log det L - 2 log 2 pi (1), pad (1).
inline constexpr int kQueryStride = 16;

/// A block of `count` <= kQueryBlock points as coordinate arrays of
/// kQueryBlock doubles each (x, y, z and, for 4-D, gray); entries from
/// `count` on must be finite (callers repeat a point) and are ignored.
struct QueryBlock {
  const double* coord[4];
  int count;
};

/// Running log-sum-exp of each point of a block: the sum is of exp(term -
/// max). Start with max = -inf and sum = 0.
struct ScoreState {
  alignas(64) double max[kQueryBlock];
  alignas(64) double sum[kQueryBlock];
  void reset() {
    for (int p = 0; p < kQueryBlock; ++p) {
      max[p] = -std::numeric_limits<double>::infinity();
      sum[p] = 0.0;
    }
  }
};

/// Running weighted moments of the regression's per-component means:
/// weights exp(term - max) summing to w, their mean `mean` of lambda, the
/// weighted sum of squared deviations from it `m2` (merged chunk by chunk as
/// in Chan et al.'s parallel variance, so nothing cancels far out), and the
/// weighted sum of the conditional variances `v`.
struct RegressState {
  alignas(64) double max[kQueryBlock];
  alignas(64) double w[kQueryBlock];
  alignas(64) double mean[kQueryBlock];
  alignas(64) double m2[kQueryBlock];
  alignas(64) double v[kQueryBlock];
  void reset() {
    for (int p = 0; p < kQueryBlock; ++p) {
      max[p] = -std::numeric_limits<double>::infinity();
      w[p] = mean[p] = m2[p] = v[p] = 0.0;
    }
  }
};

/// Adds the log-density terms of components components[0..n) (indices into
/// `params`) to `state`. `scratch` holds kQueryScratch doubles.
using QueryScoreFn = void (*)(const QueryBlock& block, const double* params, const std::uint32_t* components,
                              std::size_t n, double* scratch, ScoreState& state);
/// The same for the gray regression (3-D parameters).
using QueryRegressFn = void (*)(const QueryBlock& block, const double* params, const std::uint32_t* components,
                                std::size_t n, double* scratch, RegressState& state);

/// The kernels for this CPU: the instruction set em_kernels() chose.
struct QueryKernels {
  QueryScoreFn score3;
  QueryScoreFn score4;
  QueryRegressFn regress;
};
const QueryKernels& query_kernels();

}  // namespace sogmm::detail
