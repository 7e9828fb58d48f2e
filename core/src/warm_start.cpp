// Warm start: keep the components the new cloud still supports, seed new ones
// where it is poorly explained, then EM.
#include "sogmm/warm_start.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "parallel.hpp"
#include "point_scores.hpp"
#include "progress.hpp"
#include "sogmm/depth_quantisation.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/mean_shift.hpp"

namespace sogmm {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  return v[h];
}

// Appends component k of `from` to `to` with weight `w` (normalised later).
void append_component(Gmm& to, const Gmm& from, std::size_t k, double w) {
  to.weights.push_back(static_cast<float>(w));
  to.means.insert(to.means.end(), from.mean(k), from.mean(k) + 4);
  to.covariances.insert(to.covariances.end(), from.covariance(k), from.covariance(k) + 16);
}

// New components from k-means++ seeds among the novel points: one hard
// k-means assignment (each point to its nearest seed), then per cluster its
// mean, its per-coordinate variance + the reg_covar floor of that coordinate
// on a diagonal covariance and its size as weight. A cold start's needles
// (the floors on the diagonal, one point each)
// would lose every novel point in the first E-step to the least distant kept
// component, which then stretches over the new surface; a diagonal covariance
// is positive definite in float32 whatever the cluster's shape.
//
// The nearest seeds (N x K distances, most of this function's work) are found
// in parallel on `threads`; the sums then run serially in point order, so the
// result does not depend on the team.
Gmm seed_components(const PointsView& nv, const std::vector<std::size_t>& seeds, const RegCovarFloors& reg,
                    int threads) {
  const std::size_t k = seeds.size();
  std::vector<std::uint32_t> nearest(nv.size);
  detail::parallel_for(nv.size, threads, 256, [&](std::size_t i, int) {
    std::size_t best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < k; ++c) {
      double d = 0.0;
      for (int j = 0; j < 4; ++j) {
        const double e = static_cast<double>(nv[i][j]) - nv[seeds[c]][j];
        d += e * e;
      }
      if (d < best_d) best_d = d, best = c;
    }
    nearest[i] = static_cast<std::uint32_t>(best);
  });
  std::vector<double> sum(5 * k, 0.0), sq(4 * k, 0.0);
  float lo[4], hi[4];
  for (int j = 0; j < 4; ++j) lo[j] = hi[j] = nv[0][j];
  for (std::size_t i = 0; i < nv.size; ++i) {
    const std::size_t best = nearest[i];
    sum[5 * best] += 1.0;
    for (int j = 0; j < 4; ++j) {
      lo[j] = std::min(lo[j], nv[i][j]);
      hi[j] = std::max(hi[j], nv[i][j]);
      // Relative to the seed, so the variance does not cancel at an offset.
      const double e = static_cast<double>(nv[i][j]) - nv[seeds[best]][j];
      sum[5 * best + 1 + j] += e;
      sq[4 * best + j] += e * e;
    }
  }
  // With reg_covar = 0, a floor relative to the novel points' extent keeps a
  // one-point cluster positive definite.
  double extent = 0.0;
  for (int j = 0; j < 4; ++j) extent = std::max(extent, static_cast<double>(hi[j]) - lo[j]);
  const double relative = std::max(1e-12 * extent * extent, 1e-30);
  Gmm g;
  g.resize(k);
  std::fill(g.covariances.begin(), g.covariances.end(), 0.0f);
  for (std::size_t c = 0; c < k; ++c) {
    const double n = sum[5 * c];  // >= 1: the seed is its own nearest
    g.weights[c] = static_cast<float>(n);
    for (int j = 0; j < 4; ++j) {
      const double m = sum[5 * c + 1 + j] / n;
      g.means[4 * c + j] = static_cast<float>(nv[seeds[c]][j] + m);
      const double floor = std::max(j < 3 ? reg.spatial : reg.gray, relative);
      g.covariances[16 * c + 5 * j] = static_cast<float>(std::max(sq[4 * c + j] / n - m * m, 0.0) + floor);
    }
  }
  return g;
}

// A lower bound on the mean log-likelihood of the model's own samples,
// sum_k w_k (log w_k + E_k[log N_k]) with E_k[log N_k] = -(log det(2 pi
// Sigma_k) + 4) / 2 in 4-D: p >= w_k N_k everywhere, so E_p[log p] is at
// least this. Points that the model explains score about this much or more.
double own_log_likelihood(const Gmm& gmm) {
  constexpr double kLog2Pi = 1.8378770664093453;
  double sum = 0.0;
  for (std::size_t k = 0; k < gmm.size(); ++k) {
    const double w = gmm.weights[k];
    if (!(w > 0.0)) continue;
    double a[16], l[16];
    stored_symmetric_part(gmm.covariance(k), a);
    if (!stored_cholesky(a, l)) continue;  // validate() passed: cannot happen
    double log_det = 0.0;
    for (int i = 0; i < 4; ++i) log_det += 2.0 * std::log(l[5 * i]);
    sum += w * (std::log(w) - 0.5 * (4.0 * kLog2Pi + log_det + 4.0));
  }
  return sum;
}

}  // namespace

FitResult fit_warm(const PointsView& points, const Gmm& initial, const FitOptions& options,
                   const ProgressSink& progress, const WarmStartOptions& warm, WarmStartReport* report) {
  const ProgressScope progress_scope(progress);
  const auto t0 = std::chrono::steady_clock::now();
  require(points.size <= kMaxPoints, ErrorCode::Limit,
          "N = " + std::to_string(points.size) + " points exceeds the limit of " + std::to_string(kMaxPoints) +
              " points per fit");
  require_finite_points(points, "point cloud");
  validate(initial);
  require(options.n_init == 1, ErrorCode::InvalidArgument,
          "a warm start is one run: n_init must be 1, got " + std::to_string(options.n_init));
  require(std::isfinite(warm.min_mass) && warm.min_mass >= 0, ErrorCode::InvalidArgument,
          "warm start min_mass must be finite and >= 0, got " + checked::exact(warm.min_mass));
  require(std::isfinite(warm.novelty_nats) && warm.novelty_nats >= 0, ErrorCode::InvalidArgument,
          "warm start novelty_nats must be finite and >= 0, got " + checked::exact(warm.novelty_nats));
  require(options.em.threads >= 0, ErrorCode::InvalidArgument, "threads must be >= 0");
  require(warm.max_iter >= 0, ErrorCode::InvalidArgument,
          "warm start max_iter must be >= 0, got " + std::to_string(warm.max_iter));
  const bool fixed_k = options.n_components > 0;
  if (fixed_k)
    require(options.n_components == initial.size(), ErrorCode::InvalidArgument,
            "a fixed-K warm start needs an initial model of K = " + std::to_string(options.n_components) +
                " components, got " + std::to_string(initial.size()));
  else
    require_usable_bandwidth(options.bandwidth);
  const int threads = detail::team_size(options.em.threads);
  const detail::ScopedOmpThreads scoped(threads);
  EmOptions em = options.em;
  em.threads = threads;

  FitResult result;
  result.n_points = points.size;
  WarmStartReport rep;
  Gmm start;
  if (fixed_k) {
    start = initial;
    rep.kept = initial.size();
  } else {
    auto t = std::chrono::steady_clock::now();
    // Pass 1: every point's log-likelihood, which decides the novel points.
    const std::vector<double> ll = detail::score_points(points, initial, threads).log_likelihood;
    const double typical = median(ll);
    const double cut = typical - warm.novelty_nats;
    std::vector<char> explained(points.size);
    for (std::size_t i = 0; i < points.size; ++i) explained[i] = ll[i] >= cut;
    // Novelty is judged against the median point, so at least half of the
    // points always count as explained, even by a model far from all of them
    // (a map's last pose far away kept 1 component for 12,288 points). The
    // explained fraction in absolute terms is below one half exactly when the
    // median point scores more than novelty_nats below what the model's own
    // samples score: then the start is a cold one.
    rep.cold_fallback = typical < own_log_likelihood(initial) - warm.novelty_nats;
    // Pass 2: masses over the explained points only; a novel point far from
    // every component would otherwise lend its whole responsibility to the
    // least distant one, e.g. to a component of a surface no longer seen.
    if (!rep.cold_fallback) {
      const std::vector<double> mass = detail::score_points(points, initial, threads, &explained).mass;
      for (std::size_t k = 0; k < initial.size(); ++k) {
        if (mass[k] >= warm.min_mass && start.size() < kMaxComponents) append_component(start, initial, k, mass[k]);
      }
    }
    rep.seconds_score = seconds_since(t);
    rep.kept = start.size();
    rep.removed = initial.size() - rep.kept;

    // Novel points: all of them when nothing was kept (a cold fit).
    PointCloud novel;
    for (std::size_t i = 0; i < points.size; ++i)
      if (rep.kept == 0 || !explained[i]) novel.xyzg.insert(novel.xyzg.end(), points[i], points[i] + 4);
    rep.novel_points = novel.size();
    if (novel.size() > 0) {
      const PointsView nv = novel.view();
      detail::progress_begin(Stage::ModeCount, 0);
      t = std::chrono::steady_clock::now();
      const std::vector<double> features = range_gray_features(nv);
      const MeanShiftResult modes = options.mode_counter == ModeCounter::FlatBinned
                                        ? mean_shift_flat(features, options.bandwidth, options.mean_shift)
                                        : mean_shift_gaussian_blurring(features, options.bandwidth);
      const std::size_t room = kMaxComponents - start.size();
      const std::size_t k_new = std::min({std::max<std::size_t>(modes.size(), 1), novel.size()});
      require(k_new <= room, ErrorCode::Limit,
              "the warm start would hold " + std::to_string(start.size() + k_new) + " components, over the limit of " +
                  std::to_string(kMaxComponents) + " components per fit: use a larger bandwidth");
      result.seconds_mode_count = seconds_since(t);
      detail::progress_begin(Stage::Seeding, k_new);
      t = std::chrono::steady_clock::now();
      const std::vector<std::size_t> seeds = kmeanspp_seeds(nv, k_new, options.seed);
      const Gmm fresh = seed_components(nv, seeds, resolve_reg_covar(points, em.reg_covar), threads);
      for (std::size_t c = 0; c < fresh.size(); ++c) append_component(start, fresh, c, fresh.weights[c]);
      rep.added = seeds.size();
      result.seconds_seeding = seconds_since(t);
    }
    double total = 0.0;
    for (float w : start.weights) total += w;
    for (float& w : start.weights) w = static_cast<float>(w / total);
  }

  // The warm pass cap stands in for max_iter's default only: a max_iter the
  // user chose wins. It is for a start next to its optimum: a cold fallback
  // (or nothing kept) is a cold fit and runs to em.max_iter like one.
  if (warm.max_iter > 0 && rep.kept > 0 && em.max_iter == EmOptions{}.max_iter)
    em.max_iter = std::min(em.max_iter, warm.max_iter);
  if (dequantises(options.dequantise_depth, points) && em.quantisation.empty())
    em.quantisation = DepthQuantisation::detect(points);
  detail::progress_begin(Stage::Em, static_cast<std::uint64_t>(em.max_iter));
  const EmIterationCallback on_iteration = [](int iteration, double ll) {
    detail::progress_event(static_cast<std::uint64_t>(iteration), ll);
  };
  const auto t_em = std::chrono::steady_clock::now();
  result.gmm = fit_em_from(points, start, em, &result.em, on_iteration);
  result.seconds_em = seconds_since(t_em);
  result.run_log_likelihoods.push_back(result.em.log_likelihood);
  validate(result.gmm);
  result.seconds_total = seconds_since(t0);
  if (report) *report = rep;
  return result;
}

}  // namespace sogmm
