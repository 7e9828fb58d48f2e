// Expectation-maximisation for a full-covariance 4-D Gaussian mixture.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// Parameters of the EM. Defaults are the paper's.
struct EmOptions {
  double tol = 1e-3;        ///< stop when |change of mean log-likelihood| < tol
  double reg_covar = 1e-6;  ///< added to every covariance diagonal in every M-step
  int max_iter = 100;       ///< at most this many E+M iterations
  int threads = 0;          ///< worker threads; 0 = all available cores; at most 4 x omp_get_num_procs()
  /// 0 (default): exact E-step, every point against every component.
  /// > 0: truncated E-step (opt-in). Points are grouped into spatially compact
  /// blocks; for each block, a component is skipped when a bound proves that
  /// its log-density is below every point's best component by more than
  /// `truncation_nats`, so each skipped term weighs less than
  /// exp(-truncation_nats) of the point's largest one (25 nats: < 1.4e-11).
  /// The bound is interval arithmetic of the whitened coordinates U^T (x - mu)
  /// over the block's bounding box, compared with the per-point maxima of
  /// the components already evaluated, so it holds from the first iteration
  /// on (the tight k-means++ start included) without any fallback.
  double truncation_nats = 0.0;
};

/// What the EM did.
struct EmReport {
  int iterations = 0;             ///< E+M iterations run
  bool converged = false;         ///< stopped on tol rather than max_iter
  double log_likelihood = 0.0;    ///< mean log-likelihood per point, computed in the
                                  ///< last E-step (scikit-learn's lower_bound_)
  /// Point-component pairs evaluated / (N * M * iterations): 1 for the exact
  /// E-step, less when truncation skipped pairs.
  double pair_fraction = 1.0;
};

/// Called after each EM iteration with the iteration number (from 1) and the
/// mean log-likelihood of that iteration's E-step; may be empty.
using EmIterationCallback = std::function<void(int iteration, double log_likelihood)>;

/// Fits a GMM by EM starting from one-hot responsibilities on the seed points
/// (the paper's and scikit-learn's k-means++ initialisation): the first model
/// has means = seed points, covariances = reg_covar I and equal weights.
/// Memory is O(N + K): points are processed in fixed-size blocks through a
/// fused E+M pass, and partial sums are reduced in a fixed order, so the
/// result is bit-identical for any thread count. Parameters are float32; all
/// sums are accumulated in double across blocks.
/// Throws Error(InvalidArgument) for bad options or seed indices, and
/// Error(InvalidData) for empty or non-finite points.
Gmm fit_em(const PointsView& points, const std::vector<std::size_t>& seed_indices,
           const EmOptions& options, EmReport* report = nullptr, const EmIterationCallback& on_iteration = {});

/// Runs EM from a given model (means, covariances, weights) instead of seeds.
Gmm fit_em_from(const PointsView& points, const Gmm& initial, const EmOptions& options,
                EmReport* report = nullptr, const EmIterationCallback& on_iteration = {});

}  // namespace sogmm
