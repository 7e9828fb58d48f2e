// Greedy k-means++ seeding over a k-d tree of the points.
#include "sogmm/kmeanspp.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "parallel_stages.hpp"
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
// The points and their `closest` are also kept in tree order, so that a leaf
// is read in place rather than gathered from all over the cloud.
class SeedTree {
 public:
  SeedTree(const PointsView& points, std::vector<double>& closest, int threads) : closest_(closest) {
    // The tree is built on copies of the points that carry their index (the
    // same comparisons and moves as on an index array, read in place).
    // The per-point loops of the set-up run in spans of kSpan points on the
    // team (each element written by one span: the same values for any team);
    // serial, the set-up was about a fifth of the seeding's wall time at
    // d = 1 on two threads (issue 35).
    const std::size_t n = points.size, spans = (n + kSpan - 1) / kSpan;
    std::vector<Entry> entries(n);
    detail::parallel_for(spans, threads, 1, [&](std::size_t s, int) {
      for (std::size_t i = s * kSpan; i < std::min(n, (s + 1) * kSpan); ++i) {
        std::copy(points[i], points[i] + 4, entries[i].p);
        entries[i].index = static_cast<std::uint32_t>(i);
      }
    });
    nodes_.reserve(2 * (n / kLeafSize + 1));
    partition(entries, threads);
    build(entries, 0, n);
    order_.resize(n);
    sorted_.resize(4 * n);
    sorted_closest_.resize(n);
    detail::parallel_for(spans, threads, 1, [&](std::size_t s, int) {
      for (std::size_t k = s * kSpan; k < std::min(n, (s + 1) * kSpan); ++k) {
        order_[k] = entries[k].index;
        std::copy(entries[k].p, entries[k].p + 4, &sorted_[4 * k]);
        sorted_closest_[k] = closest_[order_[k]];
      }
    });
    find_parts(0, 0);
    // Each part's bounds on the team, then the nodes above them (each a
    // maximum of its children's: the same values as one walk).
    detail::parallel_for(parts_.size(), threads, 1, [&](std::size_t p, int) { refresh(parts_[p]); });
    settle();
  }

  /// Points per span of the set-up's per-point loops.
  static constexpr std::size_t kSpan = 16384;

  /// The disjoint subtrees ("parts") that split the work of a gain or a new
  /// seed into independent items: the nodes kPartDepth below the root (or
  /// leaves above that depth), in depth-first order.
  std::size_t parts() const { return parts_.size(); }

  /// gain(q) restricted to part p: part_gain's values, combined by
  /// gain(q, parts), are the sum over the points q would move of closest -
  /// |p - q|^2, bit for bit as one walk of the whole tree (the same
  /// additions in the same order: the walk above the parts is replayed).
  double part_gain(std::size_t p, const float* q) const { return gain(parts_[p], q); }
  double gain(const float* q, const double* part_gains) const { return combine(0, q, part_gains); }

  /// Makes q a seed in part p: lowers closest[] of the points of the part
  /// that q moves and calls moved(index) for each. The parts are disjoint,
  /// so they may be walked on any threads in any order; the skipping of
  /// nodes out of reach is exact (above), so the parts' walks change what
  /// one walk of the whole tree would. Then settle() once.
  template <typename Moved>
  void add_seed_part(std::size_t p, const float* q, Moved&& moved) {
    add_seed(parts_[p], q, moved);
  }
  /// After a seed's walks of every part: the bounds of the nodes above the
  /// parts (each its children's maximum, as refresh and add_seed keep them).
  void settle() { settle(0); }

 private:
  static constexpr std::size_t kLeafSize = 16;
  // 8 parts: with 2 + log K candidates each, a step's 16-70 items balance
  // two threads where one item per candidate left one thread waiting on
  // the costliest candidate.
  static constexpr int kPartDepth = 3;
  struct Node {
    float lo[4], hi[4];
    std::uint32_t begin, end;
    std::int32_t left = -1, right = -1;  // children; -1 for a leaf
    std::int32_t part = -1;              // index in parts_, or -1 when not a part
    double max_closest = 0.0;
  };

  struct Entry {
    float p[4];
    std::uint32_t index;
  };

  // The widest side of the box of entries [begin, end), and that box.
  static int widest_axis(const std::vector<Entry>& entries, std::size_t begin, std::size_t end, float* lo, float* hi) {
    for (int d = 0; d < 4; ++d) lo[d] = hi[d] = entries[begin].p[d];
    for (std::size_t k = begin; k < end; ++k)
      for (int d = 0; d < 4; ++d) {
        lo[d] = std::min(lo[d], entries[k].p[d]);
        hi[d] = std::max(hi[d], entries[k].p[d]);
      }
    int axis = 0;
    for (int d = 1; d < 4; ++d)
      if (static_cast<double>(hi[d]) - lo[d] > static_cast<double>(hi[axis]) - lo[axis]) axis = d;
    return axis;
  }

  // Orders the entries as the tree needs them: every range of more than
  // kLeafSize entries split at its median along its widest side
  // (deterministic: nth_element on fixed input). The ranges of one depth are
  // disjoint, so they are split in parallel, depth by depth; each sees the
  // same input as in a depth-first recursion, so the order is the same for
  // any thread count. Serial, this was about a quarter of the seeding at
  // d = 1 (issue 17).
  static void partition(std::vector<Entry>& entries, int threads) {
    std::vector<std::pair<std::size_t, std::size_t>> level{{0, entries.size()}}, next;
    while (!level.empty()) {
      next.assign(2 * level.size(), {0, 0});
      detail::parallel_for(level.size(), threads, 1, [&](std::size_t r, int) {
        const auto [begin, end] = level[r];
        if (end - begin <= kLeafSize) return;
        float lo[4], hi[4];
        const int axis = widest_axis(entries, begin, end, lo, hi);
        const std::size_t mid = begin + (end - begin) / 2;
        std::nth_element(entries.begin() + begin, entries.begin() + mid, entries.begin() + end,
                         [&](const Entry& a, const Entry& b) {
                           const float pa = a.p[axis], pb = b.p[axis];
                           return pa < pb || (pa == pb && a.index < b.index);
                         });
        next[2 * r] = {begin, mid};
        next[2 * r + 1] = {mid, end};
      });
      level.clear();
      for (const auto& range : next)
        if (range.second - range.first > kLeafSize) level.push_back(range);
    }
  }

  // The nodes over the partitioned entries, depth first; a node's box is its
  // points' (a leaf's from its entries, an inner node's from its children).
  std::int32_t build(const std::vector<Entry>& entries, std::size_t begin, std::size_t end) {
    const auto id = static_cast<std::int32_t>(nodes_.size());
    nodes_.emplace_back();
    Node node;
    node.begin = static_cast<std::uint32_t>(begin);
    node.end = static_cast<std::uint32_t>(end);
    if (end - begin > kLeafSize) {
      const std::size_t mid = begin + (end - begin) / 2;
      node.left = build(entries, begin, mid);
      node.right = build(entries, mid, end);
      const Node &l = nodes_[node.left], &r = nodes_[node.right];
      for (int d = 0; d < 4; ++d) {
        node.lo[d] = std::min(l.lo[d], r.lo[d]);
        node.hi[d] = std::max(l.hi[d], r.hi[d]);
      }
    } else {
      widest_axis(entries, begin, end, node.lo, node.hi);
    }
    nodes_[id] = node;
    return id;
  }

  // Recomputes max_closest bottom-up (after construction).
  double refresh(std::int32_t id) {
    Node& node = nodes_[id];
    if (node.left < 0) {
      node.max_closest = 0.0;
      for (std::uint32_t k = node.begin; k < node.end; ++k) node.max_closest = std::max(node.max_closest, sorted_closest_[k]);
    } else {
      node.max_closest = std::max(refresh(node.left), refresh(node.right));
    }
    return node.max_closest;
  }

  // True when no point of the node can be nearer to q than its seed. Each
  // coordinate's gap to the box, lo - q below it, q - hi above it, else 0,
  // is the largest of the three: the differences of floats in double keep
  // their signs (a nonzero one never rounds to 0), and at most one is
  // positive. As maxima rather than branches, the walks of gain and add_seed
  // do not mispredict on which side of a box q lies (the branches were a
  // large part of gain's time); the sum is the same doubles.
  bool out_of_reach(const Node& node, const float* q) const {
    double s = 0.0;
    for (int d = 0; d < 4; ++d) {
      const double below = static_cast<double>(node.lo[d]) - q[d], above = static_cast<double>(q[d]) - node.hi[d];
      const double gap = std::max(std::max(below, above), 0.0);
      s += gap * gap;
    }
    return s >= node.max_closest;
  }

  void find_parts(std::int32_t id, int depth) {
    Node& node = nodes_[id];
    if (depth == kPartDepth || node.left < 0) {
      node.part = static_cast<std::int32_t>(parts_.size());
      parts_.push_back(id);
      return;
    }
    find_parts(node.left, depth + 1);
    find_parts(node.right, depth + 1);
  }

  // The walk of gain(id, q) above the parts, with the parts' values.
  double combine(std::int32_t id, const float* q, const double* part_gains) const {
    const Node& node = nodes_[id];
    if (out_of_reach(node, q)) return 0.0;
    if (node.part >= 0) return part_gains[node.part];
    return combine(node.left, q, part_gains) + combine(node.right, q, part_gains);
  }

  double settle(std::int32_t id) {
    Node& node = nodes_[id];
    if (node.part < 0) node.max_closest = std::max(settle(node.left), settle(node.right));
    return node.max_closest;
  }

  double gain(std::int32_t id, const float* q) const {
    const Node& node = nodes_[id];
    if (out_of_reach(node, q)) return 0.0;
    if (node.left >= 0) return gain(node.left, q) + gain(node.right, q);
    // The sum over the moved points, in tree order. The savings are computed
    // for the whole leaf first (independent: they overlap), and only the
    // moved points' are added: the additions are a chain, and most points of
    // a leaf within reach do not move. Skipping a point that does not move
    // is skipping an addition of +0.0 (g starts at +0.0 and only grows), so
    // the sum is the one over all points, bit for bit.
    double saving[kLeafSize];
    std::uint32_t moved[kLeafSize], count = 0;
    for (std::uint32_t k = node.begin, j = 0; k < node.end; ++k, ++j) {
      const double d2 = dist2(&sorted_[4 * k], q), c = sorted_closest_[k];
      saving[j] = c - d2;
      moved[count] = j;
      count += d2 < c ? 1u : 0u;
    }
    double g = 0.0;
    for (std::uint32_t t = 0; t < count; ++t) g += saving[moved[t]];
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
      const double d2 = dist2(&sorted_[4 * k], q);
      if (d2 < sorted_closest_[k]) {
        sorted_closest_[k] = d2;
        closest_[order_[k]] = d2;
        moved(order_[k]);
      }
      m = std::max(m, sorted_closest_[k]);
    }
    node.max_closest = m;
  }

  std::vector<double>& closest_;
  std::vector<std::uint32_t> order_;
  std::vector<float> sorted_;           // point order_[k] at 4 k
  std::vector<double> sorted_closest_;  // closest_[order_[k]] at k
  std::vector<Node> nodes_;
  std::vector<std::int32_t> parts_;  // node ids of the parts, depth first
};

// Draws with probability proportional to closest[] as a search of u *
// potential in the running sum in index order (scikit-learn's rule), without
// rebuilding that sum each step: sums of blocks of kBlock consecutive points
// are kept and only blocks with a moved point are re-summed. The running sums
// of the block sums (prefix_) are those a walk from block 0 would form, so a
// draw is a binary search over them, and they are re-formed once per step from
// the first changed block on, not walked once per draw.
class PotentialSampler {
 public:
  explicit PotentialSampler(const std::vector<double>& closest)
      : closest_(closest),
        block_sum_((closest.size() + kBlock - 1) / kBlock),
        prefix_(block_sum_.size() + 1, 0.0),
        is_dirty_(block_sum_.size(), 0) {
    for (std::size_t b = 0; b < block_sum_.size(); ++b) resum(b);
    accumulate_from(0);
  }
  void mark(std::size_t i) {
    const std::size_t b = i / kBlock;
    if (!is_dirty_[b]) is_dirty_[b] = 1, dirty_.push_back(b);
  }
  void flush() {
    if (dirty_.empty()) return;
    for (std::size_t b : dirty_) resum(b), is_dirty_[b] = 0;
    accumulate_from(*std::min_element(dirty_.begin(), dirty_.end()));
    dirty_.clear();
  }
  /// The sum of closest[] (block sums added in order from 0.0).
  double potential() const { return prefix_.back(); }
  /// First index whose running sum exceeds target (the last index if none).
  std::size_t find(double target) const {
    const std::size_t n = closest_.size();
    // The walk "before += block_sum_[b] while before + block_sum_[b] <= target"
    // stops at the first b whose prefix_[b + 1] exceeds target (prefix_ never
    // decreases: the block sums are >= 0 and rounding is monotone), or at the
    // last block.
    const std::size_t last = block_sum_.size() - 1;
    const std::size_t b = static_cast<std::size_t>(
        std::upper_bound(prefix_.begin() + 1, prefix_.begin() + 1 + last, target) - (prefix_.begin() + 1));
    // Walk from the block found; rounding may carry the crossing into a later block.
    double running = prefix_[b];
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
  void accumulate_from(std::size_t first) {
    for (std::size_t b = first; b < block_sum_.size(); ++b) prefix_[b + 1] = prefix_[b] + block_sum_[b];
  }
  const std::vector<double>& closest_;
  std::vector<double> block_sum_;
  std::vector<double> prefix_;  // prefix_[b] = block sums 0 .. b - 1, added in order
  std::vector<std::size_t> dirty_;  // blocks with a moved point, each once
  std::vector<char> is_dirty_;
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
  detail::parallel_for((n + SeedTree::kSpan - 1) / SeedTree::kSpan, threads, 1, [&](std::size_t s, int) {
    for (std::size_t i = s * SeedTree::kSpan; i < std::min(n, (s + 1) * SeedTree::kSpan); ++i)
      closest[i] = dist2(points[i], points[centers[0]]);
  });
  detail::progress_poll();
  SeedTree tree(points, closest, threads);
  PotentialSampler sampler(closest);

  std::vector<std::size_t> candidates(trials);
  const std::size_t parts = tree.parts();
  std::vector<double> part_gain(trials * parts);
  std::vector<std::vector<std::uint32_t>> moved(parts);  // per part: the points the new seed moved
  // Candidates drawn with probability proportional to the squared distance
  // to the nearest seed (as scikit-learn: uniform * potential, searched in
  // the running sum).
  const auto draw = [&](std::size_t c) {
    detail::progress_at(c);
    const double potential = sampler.potential();
    for (int t = 0; t < trials; ++t) candidates[t] = sampler.find(rng.uniform() * potential);
  };
  if (k > 1) draw(1);
  // Step c = s + 1 is two stages: (even) the gains, per candidate and tree
  // part, in parallel; then serially the best candidate, whose potential
  // after adding it is lowest (potential - gain, where gain is what the
  // points that move to the candidate save). (odd) The new seed's walk of
  // the tree, per part in parallel; then serially the sampler's update and
  // the next step's candidates. The walk was serial (the other thread idle
  // for ~12% of the seeding's CPU at d = 1); as a stage of its own the d = 1
  // fit took 0.436 s at 2 threads near idle, against 0.453 s with the walk
  // serial and the gains split as here (issue 35). All stages run in one
  // parallel region (parallel_stages.hpp): a region per step cost a barrier
  // per step, which a loaded machine makes a scheduler slice. A gain and a
  // walk change and add what one serial walk of the whole tree would, in
  // the same order, so the seeds do not depend on the thread count.
  detail::parallel_stages(
      2 * (k - 1), threads, [&](std::size_t stage) { return stage % 2 == 0 ? trials * parts : parts; },
      [&](std::size_t stage, std::size_t i, int) {
        if (stage % 2 == 0) {
          part_gain[i] = tree.part_gain(i % parts, points[candidates[i / parts]]);
        } else {
          moved[i].clear();
          tree.add_seed_part(i, points[centers.back()], [&](std::uint32_t p) { moved[i].push_back(p); });
        }
      },
      [&](std::size_t stage) {
        if (stage % 2 == 0) {
          int best = 0;
          double best_gain = 0.0;
          for (int t = 0; t < trials; ++t) {
            const double g = tree.gain(points[candidates[t]], &part_gain[t * parts]);
            if (t == 0 || g > best_gain) best = t, best_gain = g;  // lowest potential; ties keep the first
          }
          centers.push_back(candidates[best]);
          return;
        }
        tree.settle();
        for (const auto& part : moved)
          for (std::uint32_t p : part) sampler.mark(p);
        sampler.flush();
        const std::size_t s = stage / 2;
        if (s + 2 < k) draw(s + 2);
      });
  return centers;
}

}  // namespace sogmm
