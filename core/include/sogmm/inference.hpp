// What users do with a fitted model: score, sample, regress gray, merge, move.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// How score_samples and regress_gray run. The defaults are the exact
/// queries on OpenMP's default team.
struct QueryOptions {
  /// Worker threads; 0 = OpenMP's default (omp_get_max_threads()); at most
  /// 4 x omp_get_num_procs(). Results are bitwise the same for any count.
  int threads = 0;
  /// 0 (default): exact, every point against every component. > 0: culled
  /// (opt-in), with the truncated E-step's guarantee (EmOptions::
  /// truncation_nats): a component is skipped at a point only when its term
  /// is provably more than `truncation_nats` below the point's largest one
  /// (a spatial index over 3-D boxes of the components and a bound on the
  /// rest). So a score is at most log(1 + M exp(-truncation_nats)) below the
  /// exact one (M components), and the regression is that of the mixture
  /// without components whose share of the weight at the point is below
  /// exp(-truncation_nats) each. Must be finite and >= 0.
  double truncation_nats = 0.0;
};

/// Log-density of each of `n` points under the model. `dims` = 4: rows of 4
/// floats (x, y, z, gray), joint density; `dims` = 3: rows of 3 floats (x, y,
/// z), the marginal over gray. Writes n doubles to `out`. Computed in double
/// with log-sum-exp (terms below exp(-708) of a point's largest are dropped).
/// Throws Error(InvalidArgument) for dims not 3 or 4 or bad options,
/// Error(InvalidData) for non-finite input, Error(Numeric) for an invalid model.
void score_samples(const Gmm& gmm, const float* points, std::size_t n, int dims, double* out,
                   const QueryOptions& options = {});

/// Mean of score_samples (the average log-likelihood, scikit-learn's score).
double mean_log_likelihood(const Gmm& gmm, const float* points, std::size_t n, int dims);

/// The truncation of sample's standard-normal draws unless one is given:
/// 2.5, the authors' choice (SOGMM_OPT_SAMPLE_TRUNCATION's default).
inline constexpr double kDefaultSampleTruncation = 2.5;

/// Draws `n` points from the model: per-component counts are multinomial in
/// the weights; each draw is mu + L z with L the Cholesky factor of the
/// covariance and each coordinate of z drawn independently from the standard
/// normal truncated to (-`truncation`, `truncation`) (infinity =
/// untruncated). The truncated draws invert the CDF
/// exactly, so the cost does not depend on `truncation`.
/// Rows of 4 floats (x, y, z, gray) are written to `out` grouped by component.
/// The same seed gives the same samples. `dims` = 3 writes only (x, y, z),
/// which is the 3-D marginal sampled the same way.
void sample(const Gmm& gmm, std::size_t n, std::uint64_t seed, int dims, float* out,
            double truncation = kDefaultSampleTruncation);

/// Expected gray at 3-D points, the mixture of the per-component conditionals
/// g | xyz (the paper's regression) plus one background term for points off
/// the surface: weights w_m(x) ~ pi_m N(x | mu_xyz, Sigma_xx) normalised in
/// the log domain, means lambda_m(x) = mu_g + Sigma_gx Sigma_xx^-1 (x - mu_xyz),
/// variances nu_m^2 = Sigma_gg - Sigma_gx Sigma_xx^-1 Sigma_xg. The background
/// has weight 1e-6 sum pi_m and density N(x | mu_tot, 100 Sigma_tot) (the
/// mixture's total spatial mean and covariance, widened 10x) and answers the
/// prior: gray sum pi_m mu_g / sum pi_m with the mixture's total gray variance
/// and no spatial gain. On the surface its share is ~1e-9 (the answer is the
/// paper's); beyond about 6.5 standard deviations of every component it takes
/// over, so far from the model mean and variance tend smoothly to the prior's
/// instead of extrapolating a regression line (issue 14 item 4).
/// `variance`, if not null, receives the variance of this mixture
/// conditional, sum_m w_m (nu_m^2 + (lambda_m - mean)^2) (computed about the
/// mean, so it does not cancel far out). `xyz` holds n rows of 3 floats.
/// Computed in double; `options` as for score_samples.
void regress_gray(const Gmm& gmm, const float* xyz, std::size_t n, float* mean, float* variance,
                  const QueryOptions& options = {});

/// Merges two models into one: components are concatenated and weights
/// re-weighted by support size (w = w_a S_a / (S_a + S_b) for a's
/// components). Support size 0 means unknown: if both are 0 the models count
/// equally; if only one is 0, Error(InvalidArgument) (any weighting would be a
/// guess). The support size of the result is S_a + S_b; Error(Limit) when that
/// overflows uint64.
Gmm merge(const Gmm& a, const Gmm& b);

/// Applies a rigid transform (row-major 4x4, [R t; 0 1]) to the spatial part:
/// mu_xyz -> R mu_xyz + t, Sigma_xx -> R Sigma_xx R^T, Sigma_gx -> Sigma_gx R^T.
/// Throws Error(InvalidArgument) unless rigid_pose_error(pose) is empty
/// (sogmm/model.hpp), or when a moved mean or covariance is not finite in
/// float32 (e.g. a translation of 1e39). Each moved covariance is stored in
/// float32 as the EM stores its own (plain rounding when that is positive
/// definite and within 1e-9 nats, else the nearest rounding that is), so a
/// thin component stays a valid one under any rotation. The identity returns
/// `gmm` bit for bit.
Gmm transform(const Gmm& gmm, const std::array<double, 16>& pose);

/// Bytes of the model as the paper counts them: 4 M (1 + 10 + 4).
std::size_t paper_model_bytes(const Gmm& gmm);

}  // namespace sogmm
