// The revisit refit of the map (MapOptions::revisit_refit_ratio): a frame that
// sees part of the map and would fit that part with many more components than
// the map spends on it replaces those components with a fit of its own points
// plus samples of their mass that it does not see.
#include <algorithm>
#include <cmath>
#include <limits>

#include "map_depth_view.hpp"
#include "map_state.hpp"
#include "parallel.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/mean_shift.hpp"

namespace sogmm::detail {

std::optional<RevisitRefit> plan_revisit_refit(const Map::State& s, const PointsView& points, const Pose& pose,
                                               const std::vector<double>& ll,
                                               const std::vector<std::int64_t>& dominant, std::uint64_t frame_index,
                                               const ProgressSink& progress) {
  const MapOptions& o = s.options;
  const Gmm& map = s.model.gmm;
  // A fixed K has no mode count to compare; a warm start's restore after a
  // load assumes a map that only grows by appends. (A map with components
  // has a known support size: from_model refuses 0.)
  if (!o.novelty || o.revisit_refit_ratio <= 0 || o.warm_start || o.fit.n_components > 0 || !s.camera ||
      map.size() == 0)
    return std::nullopt;
  const DepthView view(decimated(*s.camera, o.depth.decimate), o.depth, points);
  const Pose to_camera_pose = inverse_rigid(pose);

  // The map components the frame sees: means on its observed surface.
  RevisitRefit plan;
  std::vector<bool> replaced(map.size(), false);
  for (std::size_t k = 0; k < map.size(); ++k) {
    float c[4];
    to_camera(to_camera_pose, map.mean(k), c);
    if (view.classify(c) == Seen::OnSurface) {
      plan.replaced.push_back(k);
      replaced[k] = true;
    }
  }
  if (plan.replaced.empty()) return std::nullopt;

  // The frame's points the map explains (the novel ones wait for a batch as
  // usual) whose dominant component is replaced: the points under a kept
  // component stay its mass, not the refit's.
  PointCloud cloud;
  for (std::size_t i = 0; i < points.size; ++i)
    if (ll[i] >= o.novelty_threshold && dominant[i] >= 0 && replaced[static_cast<std::size_t>(dominant[i])])
      cloud.xyzg.insert(cloud.xyzg.end(), points[i], points[i] + 4);
  const std::size_t n_points = cloud.size();
  const double needed = o.revisit_refit_ratio * static_cast<double>(plan.replaced.size());
  // A fit of n points has at most n modes.
  if (static_cast<double>(n_points) < needed) return std::nullopt;

  // The number of modes a fit would give those points: the mode count of
  // fit() with the batch bandwidth and the fit's threads (not reported to
  // the progress sink: an insert that runs no fit calls none; it takes
  // milliseconds).
  FitOptions fo = o.fit;
  fo.bandwidth = refit_bandwidth(o);
  {
    const detail::ScopedOmpThreads threads(team_size(fo.em.threads));
    if (static_cast<double>(count_modes(cloud.view(), fo).size()) < needed) return std::nullopt;
  }

  // The replaced components' mass that the frame does not see (outside its
  // view, hidden behind its surfaces or where it has no depth) survives as
  // samples: as many as the points it stands for (weight x support size),
  // drawn untruncated so that a refit does not shrink it. Samples in what the
  // frame sees as free space are dropped, and those on its surfaces are
  // replaced by the frame's own points.
  Gmm sub;
  sub.resize(plan.replaced.size());
  double mass = 0.0;
  for (std::size_t j = 0; j < plan.replaced.size(); ++j) {
    const std::size_t k = plan.replaced[j];
    sub.weights[j] = map.weights[k];
    mass += map.weights[k];
    std::copy_n(map.mean(k), 4, sub.means.data() + 4 * j);
    std::copy_n(map.covariance(k), 16, sub.covariances.data() + 16 * j);
  }
  if (!(mass > 0)) return std::nullopt;
  for (float& w : sub.weights) w = static_cast<float>(w / mass);
  const double n_samples = std::round(mass * static_cast<double>(map.support_size));
  // A map whose replaced mass would not fit in one fit is left alone.
  if (!(n_samples <= static_cast<double>(kMaxPoints - n_points))) return std::nullopt;
  const std::size_t n = static_cast<std::size_t>(n_samples);
  std::vector<float> samples(4 * n);
  // The seed depends on the map's seed and the frame only: the same inserts
  // give the same map.
  if (n > 0)
    sample(sub, n, o.fit.seed ^ (0x9E3779B97F4A7C15ULL * (frame_index + 1)), 4, samples.data(),
           std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    float c[4];
    to_camera(to_camera_pose, samples.data() + 4 * i, c);
    const Seen where = view.classify(c);
    if (where == Seen::Outside || where == Seen::Hidden) cloud.xyzg.insert(cloud.xyzg.end(), c, c + 4);
  }

  // The refit improves the map; when its fit fails on the data (a limit, a
  // numeric failure) the map keeps its components. A cancel and a bad
  // option propagate.
  try {
    plan.fit = fit(cloud.view(), fo, progress);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::Limit && e.code() != ErrorCode::Numeric) throw;
    return std::nullopt;
  }
  plan.bandwidth = fo.bandwidth;
  return plan;
}

Gmm without_components(const Gmm& gmm, const std::vector<std::size_t>& removed) {
  std::vector<bool> drop(gmm.size(), false);
  for (std::size_t k : removed) drop[k] = true;
  Gmm out;
  double kept = 0.0;
  for (std::size_t k = 0; k < gmm.size(); ++k) {
    if (drop[k]) continue;
    out.weights.push_back(gmm.weights[k]);
    kept += gmm.weights[k];
    out.means.insert(out.means.end(), gmm.mean(k), gmm.mean(k) + 4);
    out.covariances.insert(out.covariances.end(), gmm.covariance(k), gmm.covariance(k) + 16);
  }
  if (out.size() == 0) return out;
  // The kept components keep their mass in points: weights renormalised over
  // them, support size the map's times their share.
  for (float& w : out.weights) w = static_cast<float>(w / kept);
  const double support = std::round(static_cast<double>(gmm.support_size) * std::min(kept, 1.0));
  out.support_size = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(support));
  return out;
}

}  // namespace sogmm::detail
