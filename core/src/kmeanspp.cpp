// Greedy k-means++ seeding over a k-d tree of the points.
#include "sogmm/kmeanspp.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "parallel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/random.hpp"

namespace sogmm {
namespace {

inline double dist2(const float* a, const float* b) {
  double s = 0.0;
  for (int i = 0; i < 4; ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    s += d * d;
  }
  return s;
}

// A static k-d tree over the points whose nodes also hold the largest
// squared distance of their points to the nearest chosen seed (`closest`).
// A new seed q can only move a point p if |p - q|^2 < closest[p], so a node
// whose box is at least `max_closest` (squared) away from q holds no point
// that q gains or moves and is skipped whole. The test is exact: a box edge
// is a point coordinate, and rounding is monotone, so the box distance as
// computed (each coordinate's gap to the box, no larger than to any member)
// never exceeds a member's distance as computed. The work per candidate is the points near it, not K clusters.
class SeedTree {
 public:
  SeedTree(const PointsView& points, std::vector<double>& closest) : points_(points), closest_(closest) {
    order_.resize(points.size);
    for (std::size_t i = 0; i < points.size; ++i) order_[i] = static_cast<std::uint32_t>(i);
    nodes_.reserve(2 * (points.size / kLeafSize + 1));
    build(0, points.size);
    refresh(0);
  }

  /// Sum over the points q would move of closest - |p - q|^2.
  double gain(const float* q) const { return gain(0, q); }

  /// Makes q a seed: lowers closest[] of the points it moves and calls
  /// moved(index) for each.
  template <typename Moved>
  void add_seed(const float* q, Moved&& moved) {
    add_seed(0, q, moved);
  }

 private:
  static constexpr std::size_t kLeafSize = 16;
  struct Node {
    float lo[4], hi[4];
    std::uint32_t begin, end;
    std::int32_t left = -1, right = -1;  // children; -1 for a leaf
    double max_closest = 0.0;
  };

  std::int32_t build(std::size_t begin, std::size_t end) {
    const auto id = static_cast<std::int32_t>(nodes_.size());
    nodes_.emplace_back();
    Node node;
    node.begin = static_cast<std::uint32_t>(begin);
    node.end = static_cast<std::uint32_t>(end);
    for (int d = 0; d < 4; ++d) node.lo[d] = node.hi[d] = points_[order_[begin]][d];
    for (std::size_t k = begin; k < end; ++k)
      for (int d = 0; d < 4; ++d) {
        node.lo[d] = std::min(node.lo[d], points_[order_[k]][d]);
        node.hi[d] = std::max(node.hi[d], points_[order_[k]][d]);
      }
    if (end - begin > kLeafSize) {
      int axis = 0;  // the widest side; the median splits it (deterministic: nth_element on fixed input)
      for (int d = 1; d < 4; ++d)
        if (static_cast<double>(node.hi[d]) - node.lo[d] > static_cast<double>(node.hi[axis]) - node.lo[axis]) axis = d;
      const std::size_t mid = begin + (end - begin) / 2;
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](std::uint32_t a, std::uint32_t b) {
                         const float pa = points_[a][axis], pb = points_[b][axis];
                         return pa < pb || (pa == pb && a < b);
                       });
      node.left = build(begin, mid);
      node.right = build(mid, end);
    }
    nodes_[id] = node;
    return id;
  }

  // Recomputes max_closest bottom-up (after construction).
  double refresh(std::int32_t id) {
    Node& node = nodes_[id];
    if (node.left < 0) {
      node.max_closest = 0.0;
      for (std::uint32_t k = node.begin; k < node.end; ++k) node.max_closest = std::max(node.max_closest, closest_[order_[k]]);
    } else {
      node.max_closest = std::max(refresh(node.left), refresh(node.right));
    }
    return node.max_closest;
  }

  // True when no point of the node can be nearer to q than its seed.
  bool out_of_reach(const Node& node, const float* q) const {
    double s = 0.0;
    for (int d = 0; d < 4; ++d) {
      double gap = 0.0;
      if (q[d] < node.lo[d]) gap = static_cast<double>(node.lo[d]) - q[d];
      else if (q[d] > node.hi[d]) gap = static_cast<double>(q[d]) - node.hi[d];
      s += gap * gap;
    }
    return s >= node.max_closest;
  }

  double gain(std::int32_t id, const float* q) const {
    const Node& node = nodes_[id];
    if (out_of_reach(node, q)) return 0.0;
    if (node.left >= 0) return gain(node.left, q) + gain(node.right, q);
    double g = 0.0;
    for (std::uint32_t k = node.begin; k < node.end; ++k) {
      const std::uint32_t i = order_[k];
      const double d2 = dist2(points_[i], q);
      if (d2 < closest_[i]) g += closest_[i] - d2;
    }
    return g;
  }

  template <typename Moved>
  void add_seed(std::int32_t id, const float* q, Moved& moved) {
    Node& node = nodes_[id];
    if (out_of_reach(node, q)) return;
    if (node.left >= 0) {
      add_seed(node.left, q, moved);
      add_seed(node.right, q, moved);
      node.max_closest = std::max(nodes_[node.left].max_closest, nodes_[node.right].max_closest);
      return;
    }
    double m = 0.0;
    for (std::uint32_t k = node.begin; k < node.end; ++k) {
      const std::uint32_t i = order_[k];
      const double d2 = dist2(points_[i], q);
      if (d2 < closest_[i]) {
        closest_[i] = d2;
        moved(i);
      }
      m = std::max(m, closest_[i]);
    }
    node.max_closest = m;
  }

  PointsView points_;
  std::vector<double>& closest_;
  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
};

// Draws with probability proportional to closest[] as a search of u *
// potential in the running sum in index order (scikit-learn's rule), without
// rebuilding that sum each step: sums of blocks of kBlock consecutive points
// are kept and only blocks with a moved point are re-summed.
class PotentialSampler {
 public:
  explicit PotentialSampler(const std::vector<double>& closest)
      : closest_(closest), block_sum_((closest.size() + kBlock - 1) / kBlock) {
    for (std::size_t b = 0; b < block_sum_.size(); ++b) resum(b);
  }
  void mark(std::size_t i) { dirty_.push_back(i / kBlock); }
  void flush() {
    std::sort(dirty_.begin(), dirty_.end());
    dirty_.erase(std::unique(dirty_.begin(), dirty_.end()), dirty_.end());
    for (std::size_t b : dirty_) resum(b);
    dirty_.clear();
  }
  double potential() const {
    double s = 0.0;
    for (double v : block_sum_) s += v;
    return s;
  }
  /// First index whose running sum exceeds target (the last index if none).
  std::size_t find(double target) const {
    const std::size_t n = closest_.size();
    double before = 0.0;
    std::size_t b = 0;
    while (b + 1 < block_sum_.size() && !(before + block_sum_[b] > target)) before += block_sum_[b++];
    // Walk from the block found; rounding may carry the crossing into a later block.
    double running = before;
    for (std::size_t i = b * kBlock; i < n; ++i)
      if ((running += closest_[i]) > target) return i;
    return n - 1;
  }

 private:
  static constexpr std::size_t kBlock = 64;
  void resum(std::size_t b) {
    double s = 0.0;
    for (std::size_t i = b * kBlock; i < std::min(closest_.size(), (b + 1) * kBlock); ++i) s += closest_[i];
    block_sum_[b] = s;
  }
  const std::vector<double>& closest_;
  std::vector<double> block_sum_;
  std::vector<std::size_t> dirty_;
};

}  // namespace

std::vector<std::size_t> kmeanspp_seeds(const PointsView& points, std::size_t k, std::uint64_t seed) {
  const std::size_t n = points.size;
  require(k >= 1 && k <= n, ErrorCode::InvalidArgument,
          "number of components must be in [1, N = " + std::to_string(n) + "], got " + std::to_string(k));
  require(n <= 0xFFFFFFFFu, ErrorCode::Limit, "k-means++: more than 2^32 - 1 points");
  require_finite_points(points, "k-means++ input");
  Rng rng(seed);
  const int trials = 2 + checked::to_int<int>(std::log(static_cast<double>(k)), "k-means++ trials");
  const int threads = detail::team_size(0);

  std::vector<std::size_t> centers;
  centers.reserve(k);
  centers.push_back(static_cast<std::size_t>(rng.next() % n));
  std::vector<double> closest(n);
  for (std::size_t i = 0; i < n; ++i) closest[i] = dist2(points[i], points[centers[0]]);
  detail::progress_poll();
  SeedTree tree(points, closest);
  PotentialSampler sampler(closest);

  std::vector<std::size_t> candidates(trials);
  std::vector<double> gain(trials);
  for (std::size_t c = 1; c < k; ++c) {
    detail::progress_at(c);
    // Candidates drawn with probability proportional to the squared distance
    // to the nearest seed (as scikit-learn: uniform * potential, searched in
    // the running sum).
    const double potential = sampler.potential();
    for (int t = 0; t < trials; ++t) candidates[t] = sampler.find(rng.uniform() * potential);
    // Potential after adding each candidate = potential - gain, where gain is
    // what the points that move to the candidate save. Candidates in parallel
    // only for large clouds: for small ones the work per step is tiny and
    // thousands of parallel regions cost more than they save. Each gain is
    // summed serially in tree order, so the result does not depend on the
    // thread count.
    detail::parallel_for(candidates.size(), n >= 65536 ? threads : 1, 1,
                         [&](std::size_t t, int) { gain[t] = tree.gain(points[candidates[t]]); });
    int best = 0;
    for (int t = 1; t < trials; ++t)
      if (gain[t] > gain[best]) best = t;  // lowest potential; ties keep the first
    centers.push_back(candidates[best]);
    tree.add_seed(points[candidates[best]], [&](std::uint32_t i) { sampler.mark(i); });
    sampler.flush();
  }
  return centers;
}

}  // namespace sogmm
