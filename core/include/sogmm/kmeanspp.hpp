// k-means++ seeding of the EM (the paper's steps 1a-1c, "greedy" variant).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// Picks K seed points by greedy k-means++ (Arthur & Vassilvitskii 2007, as
/// scikit-learn's kmeans_plusplus): the first uniformly at random, each next
/// one as the best of 2 + floor(ln K) candidates drawn with probability
/// proportional to the squared distance to the nearest chosen seed ("best" =
/// lowest resulting potential). The gains are computed over a k-d tree of the
/// points whose nodes hold their largest squared distance to the nearest
/// seed, so a candidate visits only the points it could move (exact pruning,
/// no O(K) loop over the seeds), and the running sum of the draw is kept in
/// blocks of 64 points that are re-summed only when a point in them moved
/// (a draw is a binary search over the running sums of those blocks).
/// The seeds are those of the plain O(N K trials) algorithm up to the rounding
/// of the potentials (identical in tests/core/test_kmeanspp.cpp against a
/// brute-force reference). Deterministic for a given seed, independent of
/// thread count. Returns indices into `points`.
/// Throws Error(InvalidArgument) unless 1 <= K <= N.
std::vector<std::size_t> kmeanspp_seeds(const PointsView& points, std::size_t k, std::uint64_t seed);

}  // namespace sogmm
