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
/// lowest resulting potential). Candidates whose nearest-seed cluster lies
/// entirely closer to its seed than half the distance to the candidate are
/// skipped through the triangle inequality, so the cost is far below
/// N * K * trials distance evaluations on real frames; the seeds are those
/// of the plain algorithm up to the rounding of the potentials (identical on
/// the shared frames, checked against a brute-force version). Deterministic
/// for a given seed, independent of thread count. Returns indices into
/// `points`.
/// Throws Error(InvalidArgument) unless 1 <= K <= N.
std::vector<std::size_t> kmeanspp_seeds(const PointsView& points, std::size_t k, std::uint64_t seed);

}  // namespace sogmm
