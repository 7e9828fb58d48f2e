// The truncated E-step's choice of components per block.
//
// Why a skipped term is more than `nats` below its point's best:
// 1. The bound. For x in a box B, log w_k N(x | mu_k, Sigma_k) =
//    c_k - |U_k^T (x - mu_k)|^2 / 2, and each whitened coordinate
//    y_j = sum_{i<=j} U_ij (x_i - mu_i) lies in the interval that interval
//    arithmetic gives from B; the squared distance of each interval from 0
//    bounds y_j^2 below, so upper_k(B) = c_k - sum_j gap_j^2 / 2 is at least
//    the log-density anywhere in B (up to the float32 kernel's rounding of
//    the log-density it is compared with, ~1e-5 nats, which the cut's tens of
//    nats dwarf). The bound follows the component's orientation, so thin
//    planar components are bounded tightly too.
// 2. A larger box gives a larger bound, also as computed: every step (x - mu,
//    u * x, the sum of the interval ends, max(., 0), the square, c - q / 2)
//    is monotone in its inputs under round-to-nearest, and a group's box
//    contains each of its blocks' boxes, so upper_k(block) <= upper_k(group)
//    bit for bit.
// 3. The cut. A block first evaluates some components (its warm list); the
//    lowest of its points' running maxima, minus `nats`, is its cut. A
//    component whose bound over the block is below the cut is below every
//    point's maximum, and hence every point's best, by more than `nats`.
// 4. The group's candidates. A group keeps only components whose group bound
//    is at least a threshold tau (from the previous iteration's cuts minus a
//    slack). A block whose cut is >= tau bounds only those: any other
//    component has upper_k(block) <= upper_k(group) < tau <= cut. A block
//    whose cut is below tau bounds all M components, as without groups. Either
//    way the block evaluates exactly the components with upper_k(block) >=
//    cut, in the same order, so the groups change the speed, never the fit;
//    tau depends only on per-block values of the previous iteration, so the
//    result does not depend on the thread count.
#include "em_truncation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sogmm::detail {
namespace {

// On the first iteration (no warm list yet) a block starts from this many
// components with the highest bounds.
constexpr std::size_t kFirst = 32;
// tau = (lowest previous cut of the group's blocks) - kGroupSlack. A block's
// cut moves between iterations with its worst point's maximum; a few nats
// cover nearly all moves after the first iterations, and a block that moves
// more only pays the full bound.
constexpr double kGroupSlack = 4.0;

// upper[i] = upper_k(box) for the i-th component of `bp` (see the proof above),
// by the kernel of the CPU's instruction set (em_bound_kernel.cpp). Each bound
// is the same sequence of double operations as a scalar loop, so the bounds,
// and with them the evaluated lists and the fit, do not depend on the vector
// width, nor on whether the component is one of a gathered subset.
void log_density_upper_bounds(const BoundParams& bp, const float* box, double* upper) {
  em_kernels().upper_bounds(bp.col.data(), bp.m, box, upper);
}

}  // namespace

void BoundParams::load(const std::vector<float>& params) {
  m = params.size() / kParamStride;
  col.resize(15 * m);
  for (std::size_t k = 0; k < m; ++k)
    for (int i = 0; i < 15; ++i) col[i * m + k] = params[k * kParamStride + i];
}

void BoundParams::gather(const BoundParams& all, const std::vector<std::uint32_t>& index) {
  m = index.size();
  col.resize(15 * m);
  for (int i = 0; i < 15; ++i)
    for (std::size_t j = 0; j < m; ++j) col[i * m + j] = all.col[i * all.m + index[j]];
}

TruncationMemory::TruncationMemory(std::size_t n_blocks)
    : warm(n_blocks),
      previous_cut(n_blocks, -std::numeric_limits<double>::infinity()),
      cut(n_blocks, -std::numeric_limits<double>::infinity()) {}

void TruncatedScan::load_group(std::size_t group, const float* group_box, const TruncationMemory& memory) {
  group_ = group;
  const std::size_t first = group * kGroupBlocks, last = std::min(n_blocks_, first + kGroupBlocks);
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t b = first; b < last; ++b) lowest = std::min(lowest, memory.previous_cut[b]);
  group_threshold_ = lowest - kGroupSlack;
  candidates_.clear();
  if (!(group_threshold_ > -std::numeric_limits<double>::infinity())) return;  // no cuts yet: full bounds
  upper_.resize(bounds_.m);
  log_density_upper_bounds(bounds_, group_box, upper_.data());
  for (std::size_t k = 0; k < bounds_.m; ++k)
    if (upper_[k] >= group_threshold_) candidates_.push_back(static_cast<std::uint32_t>(k));
  candidate_bounds_.gather(bounds_, candidates_);
}

void TruncatedScan::evaluate(const EmKernels& kernels, const Block& block, std::size_t b, const float* boxes,
                             const float* group_boxes, const std::vector<float>& params,
                             const std::vector<double>& exact, TruncationMemory& memory, float* rows,
                             float* row_lp_max, float* max_lp) {
  const std::size_t m = bounds_.m;
  const float* box = boxes + 8 * b;
  if (b / kGroupBlocks != group_) load_group(b / kGroupBlocks, group_boxes + 8 * (b / kGroupBlocks), memory);
  bool full_bounds = false;  // upper_ holds the block's bounds of all M components
  list_ = memory.warm[b];
  if (list_.empty()) {
    upper_.resize(m);
    log_density_upper_bounds(bounds_, box, upper_.data());
    full_bounds = true;
    std::vector<std::uint32_t> idx(m);
    for (std::size_t k = 0; k < m; ++k) idx[k] = static_cast<std::uint32_t>(k);
    const std::size_t first = std::min(m, kFirst);
    std::nth_element(idx.begin(), idx.begin() + (first - 1), idx.end(),
                     [&](std::uint32_t a, std::uint32_t c) { return upper_[a] > upper_[c]; });
    list_.assign(idx.begin(), idx.begin() + first);
    std::sort(list_.begin(), list_.end());
  }
  kernels.log_density(block, params.data(), exact.data(), list_.data(), list_.size(), rows, row_lp_max, max_lp);
  // The lowest running maximum as a vector reduction (a minimum does not
  // round; +0 and -0 give the same cut): as a scalar chain of dependent
  // minimums it was ~40% of this function's own time.
  float worst = max_lp[0];
#pragma omp simd reduction(min : worst)
  for (int p = 1; p < block.count; ++p) worst = max_lp[p] < worst ? max_lp[p] : worst;
  const double cut = static_cast<double>(worst) - nats_;
  memory.cut[b] = cut;
  const std::size_t first = list_.size();
  for (std::uint32_t k : list_) taken_[k] = 1;
  if (!full_bounds && std::isfinite(group_threshold_) && cut >= group_threshold_) {
    upper_.resize(candidate_bounds_.m);
    log_density_upper_bounds(candidate_bounds_, box, upper_.data());
    for (std::size_t i = 0; i < candidates_.size(); ++i)
      if (!taken_[candidates_[i]] && upper_[i] >= cut) list_.push_back(candidates_[i]);
  } else {
    if (!full_bounds) {
      upper_.resize(m);
      log_density_upper_bounds(bounds_, box, upper_.data());
    }
    for (std::size_t k = 0; k < m; ++k)
      if (!taken_[k] && upper_[k] >= cut) list_.push_back(static_cast<std::uint32_t>(k));
  }
  for (std::size_t i = 0; i < first; ++i) taken_[list_[i]] = 0;
  kernels.log_density(block, params.data(), exact.data(), list_.data() + first, list_.size() - first,
                      rows + first * kBlock, row_lp_max + first, max_lp);
}

void TruncatedScan::remember(std::size_t b, const float* row_max, TruncationMemory& memory) const {
  const float keep = std::exp(static_cast<float>(-nats_));
  std::vector<std::uint32_t>& warm = memory.warm[b];
  warm.clear();
  for (std::size_t i = 0; i < list_.size(); ++i)
    if (row_max[i] >= keep) warm.push_back(list_[i]);
  std::sort(warm.begin(), warm.end());
}

}  // namespace sogmm::detail
