// The culled queries' component selection (query_cull.hpp).
#include "query_cull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sogmm/checked.hpp"
#include "z_order.hpp"

namespace sogmm::detail {

QueryCuller::QueryCuller(const Gmm& gmm, const std::vector<double>& params, int dims, bool background, double nats,
                         const float* points, std::size_t n, int width, int team)
    : params_(params), dims_(dims), nats_(nats), background_(background), m_(checked::to_int<std::uint32_t>(gmm.size(), "components")),
      index_(1.0) {
  const int at = dims == 4 ? 14 : 9;  // c_k in the packed layout
  by_const_.resize(m_);
  for (std::uint32_t k = 0; k < m_; ++k) by_const_[k] = k;
  std::stable_sort(by_const_.begin(), by_const_.end(), [&](std::uint32_t a, std::uint32_t b) {
    return params[a * kQueryStride + at] > params[b * kQueryStride + at];
  });
  const_.resize(m_);
  for (std::uint32_t i = 0; i < m_; ++i) const_[i] = params[by_const_[i] * kQueryStride + at];
  // The radius (see the header); zero weights (c = -inf) sort last and are
  // left out of the percentiles.
  std::uint32_t finite = m_;
  while (finite > 0 && !std::isfinite(const_[finite - 1])) --finite;
  const double spread = finite > 0 ? const_[finite / 10] - const_[finite / 2] : 0.0;
  half_r2_ = nats + spread + 8.0;
  index_ = ComponentIndex(std::min(100.0, std::sqrt(2.0 * half_r2_)));
  half_r2_ = 0.5 * index_.sigmas() * index_.sigmas();
  index_.build(gmm);
  order_ = z_ordered(points, n, width, team);
}

void QueryCuller::choose_first(const QueryBlock& block, CullScratch& s) const {
  for (int j = 0; j < dims_; ++j) {
    s.lo[j] = s.hi[j] = block.coord[j][0];
    for (int p = 1; p < block.count; ++p) {
      s.lo[j] = std::min(s.lo[j], block.coord[j][p]);
      s.hi[j] = std::max(s.hi[j], block.coord[j][p]);
    }
  }
  Box3 box;
  for (int j = 0; j < 3; ++j) box.lo[j] = s.lo[j], box.hi[j] = s.hi[j];
  index_.query_box(box, s.candidates);
  const std::size_t nc = s.candidates.size();
  s.upper.resize(nc);
  for (std::size_t i = 0; i < nc; ++i) s.upper[i] = upper_bound(s.candidates[i], s.lo, s.hi);
  // First the components that explain a few of the block's points best
  // (kPerProbe each, by the exact term at the probe): a good first guess of
  // every point's maximum, so the cut is high from the start.
  s.first.clear();
  std::vector<std::pair<double, std::uint32_t>>& ranked = s.ranked;
  for (int probe = 0; probe < kProbes; ++probe) {
    const int p = probe * (block.count - 1) / std::max(1, kProbes - 1);
    ranked.clear();
    for (std::size_t i = 0; i < nc; ++i)
      ranked.emplace_back(-term_at(s.candidates[i], block, p), static_cast<std::uint32_t>(i));
    const std::size_t take = std::min(nc, kPerProbe);
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(take), ranked.end());
    for (std::size_t r = 0; r < take; ++r) s.first.push_back(ranked[r].second);
  }
  std::sort(s.first.begin(), s.first.end());
  s.first.erase(std::unique(s.first.begin(), s.first.end()), s.first.end());
  // Positions -> ids; mark the taken ones by a bound of +inf.
  for (std::uint32_t& i : s.first) {
    const std::uint32_t pos = i;
    i = s.candidates[pos];
    s.upper[pos] = std::numeric_limits<double>::infinity();
  }
  if (background_) s.first.push_back(m_);
}

void QueryCuller::choose_candidates(double cut, CullScratch& s) const {
  s.extra.clear();
  for (std::size_t i = 0; i < s.candidates.size(); ++i)
    if (s.upper[i] >= cut && s.upper[i] < std::numeric_limits<double>::infinity()) s.extra.push_back(s.candidates[i]);
}

void QueryCuller::choose_others(double cut, CullScratch& s) const {
  // Outside the index's answer: only a prefix by c_k can reach the cut.
  s.extra.clear();
  for (std::uint32_t i = 0; i < m_ && const_[i] - half_r2_ >= cut; ++i) {
    const std::uint32_t k = by_const_[i];
    if (!std::binary_search(s.candidates.begin(), s.candidates.end(), k) && upper_bound(k, s.lo, s.hi) >= cut)
      s.extra.push_back(k);
  }
  std::sort(s.extra.begin(), s.extra.end());
}

double QueryCuller::term_at(std::uint32_t k, const QueryBlock& block, int p) const {
  const double* q = &params_[static_cast<std::size_t>(k) * kQueryStride];
  const int d = dims_;
  const double* inv_l = q + d;
  double q2 = 0.0;
  for (int j = 0, t = 0; j < d; ++j) {
    double y = 0.0;
    for (int i = 0; i <= j; ++i, ++t) y += inv_l[t] * (block.coord[i][p] - q[i]);
    q2 += y * y;
  }
  return q[d + d * (d + 1) / 2] - 0.5 * q2;
}

double QueryCuller::upper_bound(std::uint32_t k, const double* lo, const double* hi) const {
  // Packed layout (query_kernel.hpp): mean (D), L^-1 lower row by row, c.
  const double* q = &params_[static_cast<std::size_t>(k) * kQueryStride];
  const int d = dims_;
  const double* inv_l = q + d;
  double q_min = 0.0;
  for (int j = 0, t = 0; j < d; ++j) {
    double ylo = 0.0, yhi = 0.0;
    for (int i = 0; i <= j; ++i, ++t) {
      const double a = inv_l[t] * (lo[i] - q[i]), b = inv_l[t] * (hi[i] - q[i]);
      ylo += std::min(a, b);
      yhi += std::max(a, b);
    }
    const double gap = std::max(ylo, 0.0) + std::max(-yhi, 0.0);
    q_min += gap * gap;
  }
  return q[d + d * (d + 1) / 2] - 0.5 * q_min;
}

}  // namespace sogmm::detail
