// Map-to-map merge (issue 33, "two robots, one map"; Map::merge_map in
// sogmm/map.hpp).
//
// Why not merge() of the two models: it stacks them. Where both robots saw a
// surface, each map holds its own view of it: the robot that passed close in
// fine components, the other in the coarse ones of a distant or grazing view.
// Rendered together, the first surface a ray meets wins, often the coarse
// one: on the synthetic loop (tools/sogmm-perf/two_robots.py, 300 frames) the
// stacked map scored 20.10 dB held-out pixel PSNR against 21.07 dB for the
// single-robot map, and 3.02 dB below it at frame 190.
//
// A map already has the test "does this map hold this place, and how
// sharply": the novelty test's local 3-D log-density (map_novelty.cpp), high
// on a sharply held surface, low where the map holds only a blur, -inf where
// it holds nothing. The merge applies it to components instead of a frame's
// points: each component is probed at 7 test points (its mean, and +-1 sigma
// along the three axes of its spatial covariance: where its mass is) by both
// maps. A component is outmatched when the rival map's score is at least its
// own map's (strictly above, for this map's own components: ties keep what
// this map holds) at 4 or more of them. The other map's components are
// judged first, against this whole map; then this map's against the other
// map's components that stayed. The order matters: judged at the same time,
// two overlapping components of similar sharpness could each find the other
// sharper at their own test points and both go, leaving a hole; judged in
// turn, a component only leaves for one that stays. A map merged with a copy
// of itself then keeps its own components only (every score ties), and a map
// merged into an empty one is kept whole.
//
// The kept components keep their mass in points (weight x support size;
// without_components, the rule of a revisit refit), so the merged map weighs
// each robot's surfaces by the points it saw of them. The result is one
// revision made of the steps deltas already carry (a Remove, then a Merge of
// the other map's kept components), so a receiver of this map's deltas
// follows the merge bitwise like any flush.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "component_precision.hpp"
#include "map_state.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm {
namespace {

constexpr int kTestPoints = 7;
constexpr int kMajority = 4;
// Scores this close (relative) are one sharpness, so that a tie stays a tie:
// a map's marginals keep log(weight x support) from when each component was
// added (merge() rescales the weight in float32, so the product drifts by
// ~1e-7 relative), while a copy's are computed from the rescaled weights;
// and two indexes may sum a neighbourhood in different orders. Real
// differences of sharpness are tenths of a nat and more.
constexpr double kTie = 1e-6;

// The 7 test points (x, y, z) of every component of `gmm`, in order.
std::vector<double> test_points(const Gmm& gmm) {
  std::vector<double> out(3 * kTestPoints * gmm.size());
  for (std::size_t k = 0; k < gmm.size(); ++k) {
    Eigen::Matrix3d c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c(i, j) = gmm.covariance(k)[4 * i + j];
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c);
    const Eigen::Vector3d mu(gmm.mean(k)[0], gmm.mean(k)[1], gmm.mean(k)[2]);
    double* p = out.data() + 3 * kTestPoints * k;
    for (int i = 0; i < 3; ++i) p[i] = mu[i];
    for (int a = 0; a < 3; ++a) {
      // validate(Gmm) keeps Sigma_xx positive definite; max() only guards
      // the rounding of a tiny eigenvalue.
      const Eigen::Vector3d step = std::sqrt(std::max(eig.eigenvalues()[a], 0.0)) * eig.eigenvectors().col(a);
      for (int i = 0; i < 3; ++i) {
        p[3 * (1 + 2 * a) + i] = mu[i] + step[i];
        p[3 * (2 + 2 * a) + i] = mu[i] - step[i];
      }
    }
  }
  return out;
}

std::vector<double> scores(const ComponentIndex& index, const std::vector<detail::Marginal3>& marginals, int threads,
                           const std::vector<double>& points) {
  std::vector<double> out(points.size() / 3);
  if (!marginals.empty()) detail::local_log_likelihood(index, marginals, threads, points.data(), out.size(), out.data());
  else std::fill(out.begin(), out.end(), -std::numeric_limits<double>::infinity());
  return out;
}

// The components (ascending) whose rival score is at least their own map's
// (strictly above unless ties go to the rival) at kMajority test points.
std::vector<std::size_t> outmatched(const std::vector<double>& own, const std::vector<double>& rival,
                                    bool ties_to_rival) {
  std::vector<std::size_t> out;
  const std::size_t n = own.size() / kTestPoints;
  for (std::size_t k = 0; k < n; ++k) {
    int wins = 0;
    for (int i = 0; i < kTestPoints; ++i) {
      const double o = own[kTestPoints * k + i], r = rival[kTestPoints * k + i];
      if (!(r > -std::numeric_limits<double>::infinity())) continue;
      const double tie = kTie * std::max(1.0, std::fabs(o));
      if (ties_to_rival ? r >= o - tie : r > o + tie) ++wins;
    }
    if (wins >= kMajority) out.push_back(k);
  }
  return out;
}

}  // namespace

MapMergeStats Map::merge_map(const Map& other_map, const Pose& other_to_this) {
  State& s = *s_;
  const State& o = *other_map.s_;
  require(&o != &s, ErrorCode::InvalidArgument, "map: a map cannot be merged into itself (merge a copy)");
  const std::string pose_problem = rigid_pose_error(other_to_this);
  require(pose_problem.empty(), ErrorCode::InvalidArgument,
          "map: the other map's pose in this map is not a rigid transform: " + pose_problem);
  require(s.n_pending == 0 && o.n_pending == 0, ErrorCode::InvalidArgument,
          "map: points are pending (" + std::to_string(s.n_pending) + " in this map, " +
              std::to_string(o.n_pending) + " in the other): flush both before a merge");
  require(o.model.gmm.size() > 0, ErrorCode::InvalidData, "map: the other map has no component to merge");
  if (o.camera) detail::require_map_camera(s, *o.camera, "the other map's camera");

  // This map's origin (the other's, moved, for a map that has none yet) and
  // the pose of the other map's anchored frame in this map's anchored frame:
  // rotation R, translation R o_other + t - o_this, in double.
  const bool adopt_origin = !s.origin_fixed;
  Origin origin = s.origin;
  Origin moved{};
  for (int i = 0; i < 3; ++i)
    moved[i] = other_to_this[4 * i] * o.origin[0] + other_to_this[4 * i + 1] * o.origin[1] +
               other_to_this[4 * i + 2] * o.origin[2] + other_to_this[4 * i + 3];
  if (adopt_origin) {
    detail::require_origin(moved);
    origin = moved;
  }
  Pose relative = other_to_this;
  for (int i = 0; i < 3; ++i) relative[4 * i + 3] = moved[i] - origin[i];
  const Gmm theirs = transform(o.model.gmm, relative);

  // The other map's components that this map does not already hold as
  // sharply, then this map's that those hold more sharply.
  const int threads = s.options.fit.em.threads;
  const double sigmas = s.options.index_sigmas;
  std::vector<std::size_t> skipped, removed;
  if (s.model.gmm.size() > 0) {
    const std::vector<double> points = test_points(theirs);
    const detail::Searches own = detail::searches_of(theirs, sigmas);
    skipped = outmatched(scores(own.index, own.marginals, threads, points),
                         scores(s.index, s.marginals, threads, points), true);
  }
  const Gmm kept = skipped.empty() ? theirs : detail::without_components(theirs, skipped);
  if (kept.size() > 0 && s.model.gmm.size() > 0) {
    const std::vector<double> points = test_points(s.model.gmm);
    const detail::Searches rival = detail::searches_of(kept, sigmas);
    removed = outmatched(scores(s.index, s.marginals, threads, points),
                         scores(rival.index, rival.marginals, threads, points), false);
  }

  // The merged model, its searches and frames, built aside; the commit
  // below only moves.
  detail::JournalScope journal(s.journal, s.frames.size());
  Model mine = s.model;
  if (!removed.empty()) mine.gmm = detail::without_components(s.model.gmm, removed);
  Model merged;
  if (kept.size() == 0) {
    merged = std::move(mine);
  } else {
    Model batch = o.model;
    batch.gmm = kept;
    merged = mine.gmm.size() == 0 ? std::move(batch) : merge(mine, batch);
  }
  s.journal.remove(removed);
  if (kept.size() > 0) s.journal.merge(kept);
  detail::Searches searches = detail::searches_of(merged.gmm, sigmas);
  Model world = detail::is_zero(origin) ? Model{} : detail::world_frame(merged, origin);
  std::vector<FrameStats> frames = s.frames;
  frames.reserve(s.frames.size() + o.frames.size());
  for (const FrameStats& f : o.frames) {
    FrameStats g = f;
    g.index = frames.size();
    g.pose = detail::recorded_pose(compose_poses(other_to_this, f.pose), s.options.component_precision);
    // No warm start may take these frames for the batches of this map.
    g.n_components = 0;
    frames.push_back(g);
  }

  // Commit.
  if (o.camera && !s.camera) s.camera = o.camera;
  s.origin = origin;
  s.origin_fixed = true;
  s.model = std::move(merged);
  s.index = std::move(searches.index);
  s.marginals = std::move(searches.marginals);
  s.world = std::move(world);
  s.frames = std::move(frames);
  ++s.revision;
  journal.commit(s.frames.size());

  MapMergeStats r;
  r.n_removed = removed.size();
  r.n_kept = s.model.gmm.size() - kept.size();
  r.n_added = kept.size();
  r.n_skipped = skipped.size();
  r.n_frames = o.frames.size();
  return r;
}

}  // namespace sogmm
