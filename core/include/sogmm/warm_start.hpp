// Warm start: fit a cloud starting from a model of an overlapping earlier
// cloud (the previous frame of a sequence, moved by the relative pose),
// instead of from scratch.
#pragma once

#include <cstddef>

#include "sogmm/fit.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// The thresholds of the keep / add / remove rule of a self-organizing warm start.
struct WarmStartOptions {
  /// A component of the initial model whose responsibility mass on the new
  /// cloud (sum of its responsibilities over the explained, i.e. not novel,
  /// points) is below
  /// this many points is removed: it models what the new cloud no longer sees,
  /// and EM would only shrink it to a needle on a handful of points. 0.5
  /// rather than 2: with the default pass limit, keeping the components of
  /// 0.5-2 points raised the warm fit's PSNR over seeds 0-19 on livingroom
  /// 0->1 by 0.14 dB (warm >= cold on 15 instead of 12 seeds) and 1->2 by
  /// 0.12 dB, its likelihood by 0.04 nats, at 5% more components (README,
  /// "--warm-start").
  double min_mass = 0.5;
  /// A point is poorly explained when its log-likelihood under the initial
  /// model is more than this many nats below the median point's. For a point
  /// near one component this is a squared Mahalanobis distance about
  /// 2 x 10 + 3.4 = 23.4 from it (beyond ~4.8 sigma), where a cold fit would
  /// put a component of its own.
  double novelty_nats = 10.0;
  /// The warm fit's EM pass limit while FitOptions::em.max_iter is left at
  /// its default (EmOptions{}.max_iter, 100): any other em.max_iter is the
  /// user's and wins; 0: em.max_iter alone; a cap above the default does
  /// not raise it. The model's fit record keeps the limit used
  /// (EmReport::max_iter). A warm start begins next to its
  /// optimum: EM run to `tol` spends as many passes as a cold fit, and each
  /// pass after the first few raises the likelihood but lowers PSNR (README,
  /// "--warm-start": over seeds 0-19 on livingroom 0->1 and 1->2, 8 is the
  /// smallest cap whose likelihood beats the cold fit's on every seed, at
  /// 0.20-0.23 of its time and PSNR no lower on average).
  int max_iter = 8;
};

/// What a warm start did with the initial model.
struct WarmStartReport {
  std::size_t kept = 0;     ///< initial components kept
  std::size_t removed = 0;  ///< initial components removed (mass < min_mass)
  std::size_t added = 0;    ///< new components seeded on poorly explained points
  std::size_t novel_points = 0;  ///< points poorly explained by the initial model
  /// The initial model explained fewer than half of the points (see
  /// fit_warm): the fit started cold, every point novel and kept = 0.
  bool cold_fallback = false;
  double seconds_score = 0.0;    ///< the E-step that scores the initial model
};

/// Fits `points` starting from `initial`, which must already be in the
/// points' frame (move it with transform() by the relative pose first).
/// Self-organizing (options.n_components == 0):
///  1. an exact E-step of `initial` gives every point's log-likelihood; points
///     more than warm.novelty_nats below the median are "novel". Cold
///     fallback: when the median itself is more than warm.novelty_nats below
///     the mean log-likelihood the model gives its own samples (bounded below
///     by sum_k w_k (log w_k - (log det(2 pi Sigma_k) + 4) / 2), the value
///     used), i.e. fewer than half of the points are explained in absolute
///     terms, `initial` is dropped and the fit is a cold one (every point
///     novel, report->cold_fallback): a start far from the points (a map's
///     last pose far away) would otherwise keep its nearest component for
///     all of them;
///  2. a second E-step sums each component's responsibility over the other
///     (explained) points; components with less than warm.min_mass are
///     removed (if all would be, the fit is a cold one: every point novel);
///  3. the mode count (options.bandwidth, options.mode_counter) runs on the
///     novel points only and k-means++ (options.seed) picks that many seeds
///     among them (none when no point is novel);
///  4. each novel point joins its nearest seed (one hard k-means step); a new
///     component per seed takes its cluster's mean, a diagonal covariance of
///     the cluster's variances + reg_covar and its size as weight; EM
///     (options.em) then runs from the kept components (weights: their
///     masses) plus the new ones, at most warm.max_iter passes while
///     options.em.max_iter is at its default, else (or warm.max_iter 0)
///     em.max_iter; with nothing kept (a cold fit) up to em.max_iter.
/// Fixed K (options.n_components > 0): EM from `initial` as given, which
/// must then have exactly n_components components, with the same pass limit.
/// FitResult's timings: seconds_mode_count and seconds_seeding are those of
/// step 3, the scoring of steps 1-2 is in report->seconds_score and in
/// seconds_total. The result depends on the seed only through the new
/// components, and is the same for any thread count.
/// Errors as fit(), plus Error(InvalidArgument) for n_init != 1, a K that is
/// not the initial model's size, warm thresholds that are not finite and
/// >= 0 or a negative warm.max_iter, and the errors of validate() for an invalid initial model.
FitResult fit_warm(const PointsView& points, const Gmm& initial, const FitOptions& options,
                   const ProgressSink& progress = {}, const WarmStartOptions& warm = {},
                   WarmStartReport* report = nullptr);

}  // namespace sogmm
