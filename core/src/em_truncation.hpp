// The truncated E-step's choice of components per block (private to em.cpp).
//
// Guarantee: every component a block does not evaluate has, at every point of
// the block, a log-density more than `nats` below that point's largest one.
// The proof is in em_truncation.cpp (upper bounds over boxes, and why a
// group's bound may stand in for its blocks').
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "em_kernel.hpp"

namespace sogmm::detail {

/// Blocks per bound group: the bounds of all M components are computed once
/// over the group's box, and each block of the group then bounds only the
/// group's candidates. Groups are aligned on global block indices, so they
/// are the same for every thread count.
inline constexpr std::size_t kGroupBlocks = 8;

/// The components' bound parameters as 15 columns of m doubles (mean (4), U
/// row-major upper (10), log constant (1)), so that the bound loop over
/// components vectorizes. gather() packs a subset contiguously in the same
/// layout (the group's candidates), whose bounds are then the same doubles.
struct BoundParams {
  std::size_t m = 0;
  std::vector<double> col;
  void load(const std::vector<float>& params);
  void gather(const BoundParams& all, const std::vector<std::uint32_t>& index);
};

/// Per-point-block state kept across EM iterations, read and written only by
/// the thread that processes the block in an iteration, except `cut`, which
/// is double-buffered (this iteration's values are read only in the next).
struct TruncationMemory {
  /// Per block: the components that mattered last iteration (see
  /// TruncatedScan::evaluate), empty before the first.
  std::vector<std::vector<std::uint32_t>> warm;
  /// Per block: last iteration's cut (lowest per-point maximum - nats), and
  /// this iteration's; -infinity before the first.
  std::vector<double> previous_cut, cut;
  explicit TruncationMemory(std::size_t n_blocks);
  /// Called after each completed E-step.
  void next_iteration() { previous_cut.swap(cut); }
};

/// The truncated E-step of the blocks one thread processes in order (one
/// chunk): holds the current group's candidates and scratch.
class TruncatedScan {
 public:
  TruncatedScan(const BoundParams& bounds, double nats, std::size_t n_blocks)
      : bounds_(bounds), nats_(nats), n_blocks_(n_blocks), taken_(bounds.m, 0) {}

  /// Chooses and evaluates the components of block `b`: its warm list (the
  /// first iteration: the 32 with the highest bound), then every other
  /// component whose upper bound is within `nats` of the lowest per-point
  /// maximum found. Leaves the evaluated list in `list()` (warm first, then
  /// the additions in ascending order) and its rows in `rows`; the list is
  /// the same whether or not the group's candidates were used.
  void evaluate(const EmKernels& kernels, const Block& block, std::size_t b, const float* boxes,
                const float* group_boxes, const std::vector<float>& params, const std::vector<double>& exact,
                TruncationMemory& memory, float* rows, float* row_lp_max, float* max_lp);
  /// Keeps for the next iteration the evaluated components whose largest
  /// responsibility-scale value exp(lp - max) in the block (`row_max`, as
  /// em_finish leaves it) is at least exp(-nats).
  void remember(std::size_t b, const float* row_max, TruncationMemory& memory) const;
  const std::vector<std::uint32_t>& list() const { return list_; }

 private:
  void load_group(std::size_t group, const float* group_box, const TruncationMemory& memory);

  const BoundParams& bounds_;
  double nats_;
  std::size_t n_blocks_;
  std::size_t group_ = static_cast<std::size_t>(-1);
  // Every non-candidate's bound over the group's box is below it; -infinity
  // when there are no candidates (the first iteration: no cuts yet).
  double group_threshold_ = 0.0;
  std::vector<std::uint32_t> candidates_;  // ascending
  BoundParams candidate_bounds_;
  std::vector<double> upper_;
  std::vector<char> taken_;
  std::vector<std::uint32_t> list_;
};

}  // namespace sogmm::detail
