// The disc tree and its exact nearest-disc search (disc_tree.hpp).
#include "disc_tree.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sogmm::detail {

namespace {

// Discs per leaf: a leaf's discs are bounded one by one (a few flops each),
// so small leaves trade box tests against disc bounds.
constexpr std::uint32_t kLeaf = 4;

// Squared distance of x to the box [lo, hi] (0 inside).
double box_distance2(const double* lo, const double* hi, const Eigen::Vector3d& x) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max(std::max(lo[k] - x(k), x(k) - hi[k]), 0.0);
    s += g * g;
  }
  return s;
}

}  // namespace

DiscTree::DiscTree(const std::vector<Disc>& discs) {
  const std::size_t m = discs.size();
  // Each disc's box: the ellipse mu + a cos(t) e1 + b sin(t) e2 reaches
  // sqrt((a e1_k)^2 + (b e2_k)^2) from mu along axis k; the pad covers the
  // rounding of that arithmetic.
  std::vector<Eigen::Array3d> lo(m), hi(m);
  double largest = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const Disc& d = discs[i];
    const Eigen::Array3d half =
        ((d.a * d.e1.array()).square() + (d.b * d.e2.array()).square()).sqrt();
    const Eigen::Array3d pad = 1e-9 * (half + d.mu.array().abs());
    lo[i] = d.mu.array() - half - pad;
    hi[i] = d.mu.array() + half + pad;
    largest = std::max({largest, lo[i].abs().maxCoeff(), hi[i].abs().maxCoeff()});
  }
  slack_ = 1e-9 * (1.0 + largest);
  std::vector<std::uint32_t> ids(m);
  std::iota(ids.begin(), ids.end(), 0u);
  nodes_.reserve(2 * (m / kLeaf + 1));
  build(ids, 0, static_cast<std::uint32_t>(m), discs, lo, hi);
  id_ = ids;
  discs_.resize(m);
  at_.resize(m);
  for (std::uint32_t k = 0; k < m; ++k) {
    discs_[k] = discs[ids[k]];
    at_[ids[k]] = k;
  }
}

std::uint32_t DiscTree::build(std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                              const std::vector<Disc>& discs, const std::vector<Eigen::Array3d>& lo,
                              const std::vector<Eigen::Array3d>& hi) {
  const auto self = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Array3d box_lo = lo[ids[begin]], box_hi = hi[ids[begin]];
  Eigen::Array3d c_lo = discs[ids[begin]].mu.array(), c_hi = c_lo;
  for (std::uint32_t k = begin + 1; k < end; ++k) {
    box_lo = box_lo.min(lo[ids[k]]);
    box_hi = box_hi.max(hi[ids[k]]);
    c_lo = c_lo.min(discs[ids[k]].mu.array());
    c_hi = c_hi.max(discs[ids[k]].mu.array());
  }
  for (int k = 0; k < 3; ++k) {
    nodes_[self].lo[k] = box_lo(k);
    nodes_[self].hi[k] = box_hi(k);
  }
  if (end - begin <= kLeaf) {
    nodes_[self].first = begin;
    nodes_[self].count = end - begin;
    return self;
  }
  // Split at the median centre along the centres' longest extent (ties by
  // id, so that the tree does not depend on the library's nth_element).
  int axis = 0;
  (c_hi - c_lo).maxCoeff(&axis);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, [&](std::uint32_t p, std::uint32_t q) {
    const double a = discs[p].mu(axis), b = discs[q].mu(axis);
    return a < b || (a == b && p < q);
  });
  build(ids, begin, mid, discs, lo, hi);
  const std::uint32_t second = build(ids, mid, end, discs, lo, hi);
  nodes_[self].first = second;
  return self;
}

void DiscTree::visit(std::uint32_t k, const Eigen::Vector3d& x, double slack, Nearest& best) const {
  const std::uint32_t id = id_[k];
  if (id == best.id) return;
  const Disc& d = discs_[k];
  // The disc lies in its plane within `radius` of mu: with c the offset
  // along the normal and rho the in-plane distance from mu, its distance is
  // at least sqrt(c^2 + max(0, rho - radius)^2).
  const Eigen::Vector3d r = x - d.mu;
  const double c = r.dot(d.normal);
  const double rim = std::max(0.0, std::sqrt(std::max(0.0, r.squaredNorm() - c * c)) - d.radius);
  const double limit = best.distance + slack;
  if (c * c + rim * rim > limit * limit) return;
  Eigen::Vector3d from;
  const double dist = disc_distance(d, x, from);
  if (dist < best.distance || (dist == best.distance && id < best.id)) {
    best.distance = dist;
    best.id = id;
    best.from = from;
  }
}

double DiscTree::upper_bound(std::uint32_t id, const Eigen::Vector3d& x) const {
  const Disc& d = discs_[at_[id]];
  const Eigen::Vector3d r = x - d.mu;
  const double s = r.dot(d.e1), t = r.dot(d.e2), c = r.dot(d.normal);
  const double q = (s / d.a) * (s / d.a) + (t / d.b) * (t / d.b);
  if (q <= 1.0) return std::abs(c);
  const double shrink = 1.0 - 1.0 / std::sqrt(q);
  return std::sqrt((s * shrink) * (s * shrink) + (t * shrink) * (t * shrink) + c * c);
}

void DiscTree::leaves_near(const double lo[3], const double hi[3], double bound, std::vector<std::uint32_t>& leaves,
                           std::vector<std::uint32_t>& stack) const {
  double largest = 0.0;
  for (int k = 0; k < 3; ++k) largest = std::max({largest, std::abs(lo[k]), std::abs(hi[k])});
  const double limit = bound + slack_ + 1e-9 * largest;
  const auto within = [&](const Node& nd) {
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double g = std::max(std::max(nd.lo[k] - hi[k], lo[k] - nd.hi[k]), 0.0);
      s += g * g;
    }
    return s <= limit * limit;
  };
  leaves.clear();
  stack.assign(1, 0u);
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    const Node& nd = nodes_[node];
    if (!within(nd)) continue;
    if (nd.count > 0) {
      leaves.push_back(node);
    } else {
      stack.push_back(nd.first);
      stack.push_back(node + 1);
    }
  }
}

DiscTree::Nearest DiscTree::nearest_among(const Eigen::Vector3d& x, std::uint32_t hint,
                                          const std::vector<std::uint32_t>& leaves) const {
  Nearest best;
  best.id = hint;
  best.distance = disc_distance(discs_[at_[hint]], x, best.from);
  const double slack = slack_ + 1e-9 * x.cwiseAbs().maxCoeff();
  for (const std::uint32_t leaf : leaves) {
    const Node& nd = nodes_[leaf];
    const double limit = best.distance + slack;
    if (box_distance2(nd.lo, nd.hi, x) > limit * limit) continue;
    for (std::uint32_t k = nd.first; k < nd.first + nd.count; ++k) visit(k, x, slack, best);
  }
  return best;
}

bool DiscTree::nearest_face_among(const Eigen::Vector3d& x, double limit, const std::vector<std::uint32_t>& leaves,
                                  Nearest& face) const {
  bool found = false;
  const double slack = slack_ + 1e-9 * x.cwiseAbs().maxCoeff();  // as nearest_among's
  for (const std::uint32_t leaf : leaves) {
    const Node& nd = nodes_[leaf];
    const double reach = (found ? face.distance : limit) + slack;  // the box is never the one that decides
    if (box_distance2(nd.lo, nd.hi, x) > reach * reach) continue;
    for (std::uint32_t k = nd.first; k < nd.first + nd.count; ++k) {
      const Disc& d = discs_[k];
      const double c = (x - d.mu).dot(d.normal);
      if (std::abs(c) > (found ? face.distance : limit) || !over_face(d, x)) continue;
      if (found && std::abs(c) == face.distance && id_[k] > face.id) continue;
      found = true;
      face.distance = std::abs(c);
      face.id = id_[k];
      face.from = c * d.normal;
    }
  }
  return found;
}

DiscTree::Nearest DiscTree::nearest(const Eigen::Vector3d& x, std::uint32_t hint,
                                    std::vector<std::pair<double, std::uint32_t>>& stack) const {
  Nearest best;
  best.id = hint;
  best.distance = disc_distance(discs_[at_[hint]], x, best.from);
  const double slack = slack_ + 1e-9 * x.cwiseAbs().maxCoeff();
  const auto within = [&](double d2) {
    const double limit = best.distance + slack;
    return d2 <= limit * limit;
  };
  // Depth first, the nearer child first; a subtree is entered only while
  // its box may hold a disc as near as the best so far.
  stack.clear();
  std::uint32_t node = 0;
  if (!within(box_distance2(nodes_[0].lo, nodes_[0].hi, x))) return best;
  for (;;) {
    const Node& nd = nodes_[node];
    if (nd.count > 0) {
      for (std::uint32_t k = nd.first; k < nd.first + nd.count; ++k) visit(k, x, slack, best);
    } else {
      const std::uint32_t left = node + 1, right = nd.first;
      const double dl = box_distance2(nodes_[left].lo, nodes_[left].hi, x);
      const double dr = box_distance2(nodes_[right].lo, nodes_[right].hi, x);
      const bool left_first = dl <= dr;
      const std::uint32_t near = left_first ? left : right, far = left_first ? right : left;
      const double d_near = left_first ? dl : dr, d_far = left_first ? dr : dl;
      if (within(d_far)) stack.emplace_back(d_far, far);
      if (within(d_near)) {
        node = near;
        continue;
      }
    }
    // The next subtree that may still hold a nearer disc.
    for (;;) {
      if (stack.empty()) return best;
      const auto [d2, next] = stack.back();
      stack.pop_back();
      if (within(d2)) {
        node = next;
        break;
      }
    }
  }
}

}  // namespace sogmm::detail
