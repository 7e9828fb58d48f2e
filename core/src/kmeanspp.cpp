// Greedy k-means++ seeding with triangle-inequality pruning.
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

// Points grouped by their nearest chosen seed. `radius` of a cluster is the
// largest distance of a member to its seed: a candidate at distance D >= 2 *
// radius from the seed cannot be nearer than the seed to any member
// (triangle inequality), so the whole cluster is skipped.
struct Clusters {
  std::vector<std::vector<std::uint32_t>> members;
  std::vector<double> radius;
};

}  // namespace

std::vector<std::size_t> kmeanspp_seeds(const PointsView& points, std::size_t k, std::uint64_t seed) {
  const std::size_t n = points.size;
  require(k >= 1 && k <= n, ErrorCode::InvalidArgument,
          "number of components must be in [1, N = " + std::to_string(n) + "], got " + std::to_string(k));
  require_finite_points(points, "k-means++ input");
  Rng rng(seed);
  const int trials = 2 + checked::to_int<int>(std::log(static_cast<double>(k)), "k-means++ trials");
  const int threads = detail::team_size(0);

  std::vector<std::size_t> centers;
  centers.reserve(k);
  centers.push_back(static_cast<std::size_t>(rng.next() % n));
  std::vector<double> closest(n);
  for (std::size_t i = 0; i < n; ++i) closest[i] = dist2(points[i], points[centers[0]]);
  Clusters clusters;
  clusters.members.emplace_back(n);
  for (std::size_t i = 0; i < n; ++i) clusters.members[0][i] = static_cast<std::uint32_t>(i);
  clusters.radius.push_back(std::sqrt(*std::max_element(closest.begin(), closest.end())));

  std::vector<double> cumulative(n);
  std::vector<std::size_t> candidates(trials);
  std::vector<double> gain(trials);
  for (std::size_t c = 1; c < k; ++c) {
    // Candidates drawn with probability proportional to the squared distance
    // to the nearest seed (as scikit-learn: uniform * potential, searched in
    // the running sum).
    double running = 0.0;
    for (std::size_t i = 0; i < n; ++i) cumulative[i] = (running += closest[i]);
    const double potential = running;
    for (int t = 0; t < trials; ++t) {
      const double target = rng.uniform() * potential;
      const std::size_t idx = std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin();
      candidates[t] = std::min(idx, n - 1);
    }
    // Potential after adding each candidate = potential - gain, where gain is
    // what the points that move to the candidate save.
    // Candidates in parallel only for large clouds: for small ones the work
    // per step is tiny and thousands of parallel regions cost more than they
    // save. Each gain is summed serially, so the result does not depend on
    // the thread count.
    detail::parallel_for(candidates.size(), n >= 65536 ? threads : 1, 1, [&](std::size_t t, int) {
      const float* cand = points[candidates[t]];
      double g = 0.0;
      for (std::size_t a = 0; a < clusters.members.size(); ++a) {
        const double d = std::sqrt(dist2(cand, points[centers[a]]));
        if (d >= 2.0 * clusters.radius[a]) continue;
        for (std::uint32_t i : clusters.members[a]) {
          const double d2 = dist2(points[i], cand);
          if (d2 < closest[i]) g += closest[i] - d2;
        }
      }
      gain[t] = g;
    });
    int best = 0;
    for (int t = 1; t < trials; ++t)
      if (gain[t] > gain[best]) best = t;  // lowest potential; ties keep the first
    const std::size_t chosen = candidates[best];
    const float* cand = points[chosen];
    centers.push_back(chosen);
    // Move the points that are now nearer to the new seed.
    std::vector<std::uint32_t> moved;
    for (std::size_t a = 0; a < clusters.members.size(); ++a) {
      const double d = std::sqrt(dist2(cand, points[centers[a]]));
      if (d >= 2.0 * clusters.radius[a]) continue;
      auto& mem = clusters.members[a];
      double r2 = 0.0;
      std::size_t keep = 0;
      for (std::uint32_t i : mem) {
        const double d2 = dist2(points[i], cand);
        if (d2 < closest[i]) {
          closest[i] = d2;
          moved.push_back(i);
        } else {
          mem[keep++] = i;
          r2 = std::max(r2, closest[i]);
        }
      }
      mem.resize(keep);
      clusters.radius[a] = std::sqrt(r2);
    }
    double r2 = 0.0;
    for (std::uint32_t i : moved) r2 = std::max(r2, closest[i]);
    clusters.members.push_back(std::move(moved));
    clusters.radius.push_back(std::sqrt(r2));
  }
  return centers;
}

}  // namespace sogmm
