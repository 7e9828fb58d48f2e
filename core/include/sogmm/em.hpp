// Expectation-maximisation for a full-covariance 4-D Gaussian mixture.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "sogmm/depth_quantisation.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"
#include "sogmm/reg_covar.hpp"

namespace sogmm {

/// How the EM moves from one model to the next (EmOptions::acceleration).
/// The values are the C API's (SOGMM_OPT_EM_ACCELERATION).
enum class EmAcceleration : int {
  None = 0,     ///< plain EM: each model is the M-step of the last
  Squarem = 1,  ///< SQUAREM (Varadhan & Roland 2008, S3) with a monotone safeguard
};

/// Parameters of the EM. Defaults are the paper's.
struct EmOptions {
  double tol = 1e-3;        ///< stop when |change of mean log-likelihood| < tol
  /// Added to the covariance diagonals in every M-step (and the seeds'
  /// covariances), in the data's units squared. Unset (default, "auto"):
  /// floors derived from the data's scales, one on x, y, z and one on gray
  /// (auto_reg_covar in sogmm/reg_covar.hpp: the paper's 1e-6 m^2 for a
  /// room-sized scene with gray in [0, 1], 1 m^2 for a 1 km plane). Set: the
  /// user's value on all four diagonals, as given (>= 0, finite). The floors
  /// the fit adds on its own are relative: the loading that rescues a
  /// covariance that is not positive definite starts at 1e-12 of the
  /// component's largest variance (of the data's extent squared when it has
  /// none), and the float32 storage of a covariance keeps it positive definite
  /// with the least change (see fit_em).
  std::optional<double> reg_covar;
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
  /// on (the tight k-means++ start included) without any fallback. From the
  /// second iteration on, all components are bounded once per group of 8
  /// blocks and each block bounds only the group's candidates (those within
  /// a slack of the previous iteration's cuts; a block whose cut fell below
  /// bounds all), which evaluates the same components (em_truncation.cpp).
  double truncation_nats = 0.0;
  /// Depth quantisation of the points (empty by default: none). When set, every
  /// M-step floors each component's variance along its viewing ray at the
  /// quantisation bin's (DepthQuantisation::floor_covariance_at), so no
  /// component collapses onto one depth level. fit() detects it for
  /// camera-frame clouds.
  DepthQuantisation quantisation;
  /// None (default): plain EM. Squarem: after every two EM steps t1 =
  /// F(t0), t2 = F(t1), the model is extrapolated along them (t0 + 2a r +
  /// a^2 v, r = t1 - t0, v = t2 - 2 t1 + t0, a = |r| / |v| in t0's Fisher
  /// metric, capped by a schedule that grows while steps succeed) and one EM
  /// step is taken from there. A component whose extrapolation is not one
  /// (a covariance not positive definite, or not above its reg_covar floors,
  /// as for a component of fewer points than dimensions) takes the plain
  /// step t2 while the others extrapolate, and an extrapolation whose
  /// log-likelihood is below t1's is rejected, the run continuing from t2 as
  /// plain EM would (measured on livingroom frame 0, d = 5, bandwidth 0.02,
  /// seeds 0-4: 43.6 passes against plain EM's 55.6, likelihood, held-out
  /// likelihood and PSNR within the seed spread). The model returned is an M-step's. Limit: the EM
  /// step after a kept extrapolation is not an ascent step (the M-step adds
  /// the reg_covar floors back), so the reported log-likelihood can fall
  /// there (measured: up to 2.5e-4 nats/point on a synthetic scene, where
  /// plain EM never falls; test_em_acceleration.cpp).
  /// Iterations (max_iter, EmReport::iterations) count E+M passes, rejected
  /// ones included; tol applies between consecutive reported passes.
  EmAcceleration acceleration = EmAcceleration::None;
  /// 0 (default): EM stops when a pass changes the mean log-likelihood by
  /// less than `tol`. c > 0: also when it changes it by less than c times
  /// the mean's own standard error (sd / sqrt(N), sd the standard deviation
  /// of the E-step's per-point log-likelihoods: EmReport::standard_error),
  /// whichever is larger. The mean of N points' log-likelihoods is known to
  /// that standard error only (another sample of the same surfaces moves it
  /// by about as much), so passes that gain a small fraction of it refine
  /// the fit to these points, not to the scene. tol = 0 still runs max_iter
  /// passes.
  double tol_standard_errors = 0.0;
};

/// What the EM did.
struct EmReport {
  int iterations = 0;             ///< E+M iterations run
  int max_iter = 0;               ///< the iteration limit it ran under (EmOptions::max_iter)
  bool converged = false;         ///< stopped on tol rather than max_iter
  double log_likelihood = 0.0;    ///< mean log-likelihood per point, computed in the
                                  ///< last E-step (scikit-learn's lower_bound_)
  /// Standard error of that mean: the per-point log-likelihoods' standard
  /// deviation over sqrt(N), in the last E-step (what
  /// EmOptions::tol_standard_errors scales). Measured only when
  /// tol_standard_errors > 0 (its per-point logs cost 16 times the E-step's
  /// others); 0 otherwise.
  double standard_error = 0.0;
  /// Point-component pairs evaluated / (N * M * iterations): 1 for the exact
  /// E-step, less when truncation skipped pairs.
  double pair_fraction = 1.0;
  /// The SIMD kernel that ran the E-step: "avx512", "avx2" or "sse2" (the
  /// best the CPU supports, capped by the SOGMM_ISA environment variable).
  const char* kernel = "";
  /// The regulariser the fit used (EmOptions::reg_covar resolved).
  RegCovarFloors reg_covar;
  /// EmAcceleration::Squarem: extrapolations kept and rejected (each costs
  /// one pass; 0 and 0 for plain EM).
  int extrapolations_kept = 0;
  int extrapolations_rejected = 0;
};

/// Called after each EM iteration with the iteration number (from 1) and the
/// mean log-likelihood of that iteration's E-step; may be empty.
using EmIterationCallback = std::function<void(int iteration, double log_likelihood)>;

/// Fits a GMM by EM starting from one-hot responsibilities on the seed points
/// (the paper's and scikit-learn's k-means++ initialisation): the first model
/// has means = seed points, covariances = the reg_covar floors on the diagonal
/// and equal weights.
/// Memory is O(N + threads x 257 x K + 16 x 15 x K): points are processed in
/// fixed-size blocks through a fused E+M pass (scratch per thread), and
/// partial sums of up to 16 chunks are reduced in a fixed order, so the
/// result is bit-identical for any thread count.
/// Precision: the fit works relative to the midpoint of the data's bounding
/// box, so a cloud far from the origin is fitted as well as the same cloud at
/// the origin; means and covariances are held in double between iterations
/// (the block kernels run in float32, sums accumulate in double; a component
/// too elongated for float32 arithmetic, such as a 1 km plane with 1 cm
/// noise, is evaluated and accumulated in double, and an iteration whose
/// M-step first makes a component that elongated is repeated with it in
/// double, so the log-likelihood never falls by more than rounding). Every
/// covariance that leaves the fit is checked in double and rounded to float32
/// so that it stays positive definite (an eigenvalue floor relative to the
/// component's own largest eigenvalue only if no rounding is), so the model
/// returned always passes validate().
/// Throws Error(InvalidArgument) for bad options or seed indices, and
/// Error(InvalidData) for empty or non-finite points.
Gmm fit_em(const PointsView& points, const std::vector<std::size_t>& seed_indices,
           const EmOptions& options, EmReport* report = nullptr, const EmIterationCallback& on_iteration = {});

/// Runs EM from a given model (means, covariances, weights) instead of seeds.
Gmm fit_em_from(const PointsView& points, const Gmm& initial, const EmOptions& options,
                EmReport* report = nullptr, const EmIterationCallback& on_iteration = {});

}  // namespace sogmm
