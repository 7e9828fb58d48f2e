// The whole fit: mode count -> k-means++ -> EM.
#include "sogmm/fit.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <string>

#include "parallel.hpp"
#include "progress.hpp"
#include "sogmm/depth_quantisation.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/options.hpp"

namespace sogmm {
namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

MeanShiftResult count_modes(const PointsView& points, const FitOptions& options) {
  const std::vector<double> features = range_gray_features(points);
  detail::progress_poll();
  return options.mode_counter == ModeCounter::FlatBinned
             ? mean_shift_flat(features, options.bandwidth, options.mean_shift)
             : mean_shift_gaussian_blurring(features, options.bandwidth);
}

bool dequantises(Dequantise setting, const PointsView& points) {
  return setting == Dequantise::On || (setting == Dequantise::Auto && points.from_depth_image);
}

FitResult fit(const PointsView& points, const FitOptions& options, const ProgressSink& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  // Limits first: nothing is read or allocated for an oversized request.
  require(points.size <= kMaxPoints, ErrorCode::Limit,
          "N = " + std::to_string(points.size) + " points exceeds the limit of " + std::to_string(kMaxPoints) +
              " points per fit");
  require_finite_points(points, "point cloud");
  const bool fixed_k = options.n_components > 0;
  if (!fixed_k) {
    require_usable_bandwidth(options.bandwidth);
  } else {
    require(options.n_components <= points.size, ErrorCode::InvalidArgument,
            "number of components K = " + std::to_string(options.n_components) +
                " exceeds the number of points N = " + std::to_string(points.size));
    require(options.n_components <= kMaxComponents, ErrorCode::Limit,
            "K = " + std::to_string(options.n_components) + " components exceeds the limit of " +
                std::to_string(kMaxComponents) + " components per fit");
  }
  require_option(OptionKey::THREADS, std::int64_t{options.em.threads}, "threads");
  require_option(OptionKey::N_INIT, std::int64_t{options.n_init}, "n_init (number of runs)");
  // Every parallel loop of the fit (mode count, seeding, EM) uses this many.
  const int threads = detail::team_size(options.em.threads);
  const detail::ScopedOmpThreads scoped_threads(threads);
  const ProgressScope progress_scope(progress);

  FitResult result;
  result.n_points = points.size;
  std::size_t k = options.n_components;
  if (!fixed_k) {
    detail::progress_begin(Stage::ModeCount, 0);
    const auto t = std::chrono::steady_clock::now();
    const MeanShiftResult modes = count_modes(points, options);
    k = std::min<std::size_t>(std::max<std::size_t>(modes.size(), 1), points.size);
    require(k <= kMaxComponents, ErrorCode::Limit,
            "the mode count found " + std::to_string(k) + " components with bandwidth " +
                checked::exact(options.bandwidth) + ", over the limit of " + std::to_string(kMaxComponents) +
                " components per fit: use a larger bandwidth");
    result.seconds_mode_count = seconds_since(t);
  }

  EmOptions em = options.em;
  em.threads = threads;
  // Quantised depth lets components collapse onto single depth levels (see
  // DepthQuantisation); on request, fit the dequantised depths instead.
  if (dequantises(options.dequantise_depth, points) && em.quantisation.empty())
    em.quantisation = DepthQuantisation::detect(points);
  const EmIterationCallback on_iteration = [](int iteration, double ll) {
    detail::progress_event(static_cast<std::uint64_t>(iteration), ll);
  };
  // Runs are sequential, each using every thread, so the kept model is the
  // same for any thread count.
  for (int run = 0; run < options.n_init; ++run) {
    if (options.n_init > 1)
      detail::progress_begin(Stage::Run, static_cast<std::uint64_t>(options.n_init), static_cast<std::uint64_t>(run) + 1,
                             run == 0 ? 0.0 : result.em.log_likelihood);
    detail::progress_begin(Stage::Seeding, k);
    auto t = std::chrono::steady_clock::now();
    const std::vector<std::size_t> seeds = kmeanspp_seeds(points, k, options.seed + static_cast<std::uint64_t>(run));
    result.seconds_seeding += seconds_since(t);

    detail::progress_begin(Stage::Em, static_cast<std::uint64_t>(em.max_iter));
    t = std::chrono::steady_clock::now();
    EmReport report;
    Gmm gmm = fit_em(points, seeds, em, &report, on_iteration);
    result.seconds_em += seconds_since(t);
    result.run_log_likelihoods.push_back(report.log_likelihood);
    if (run == 0 || report.log_likelihood > result.em.log_likelihood) {
      result.gmm = std::move(gmm);
      result.em = report;
      result.run = run;
    }
  }

  validate(result.gmm);
  result.seconds_total = seconds_since(t0);
  return result;
}

}  // namespace sogmm
