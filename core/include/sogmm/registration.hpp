// Rigid registration of a point cloud or of a fitted model to a model (issue
// 32): the pose that best explains the source points (x, y, z, gray), or the
// source model's components (register_model, D2D), under a target Gmm.
//
// The objective. The transformed source points x_i = R p_i + t are scored by
// the target's 3-D marginal mixed with a uniform outlier density:
//   p(x) = (1 - eps) sum_k pi_k N(x; mu_k, Sigma_k + s^2 I) + eps / V,
// eps = outlier_ratio, V the volume of the target's 3-sigma box, s the
// smoothing of the current level. The pose maximises sum_i log p(x_i). Each
// iteration scores every point once: responsibilities w_ik, the gradient, the
// complete-data information sum_ik w_ik J^T P_k J (P_k = (Sigma_k + s^2 I)^-1,
// J over a left perturbation of the pose) and Louis' spread (below). A point
// source then takes a Newton step on the log-likelihood, whose curvature is
// the observed information (the first minus the spread), capped at 3
// Gauss-Newton steps; where the observed information holds some direction
// less than 1e-4 as firmly as the best-held one (or not at all) it takes the
// Gauss-Newton (EM) step of sum_ik w_ik (x_i - mu_k)^T P_k (x_i - mu_k) / 2
// instead, as a model source always does. Newton converges quadratically
// where EM is linear and slow along weakly held directions (the synthetic
// loop's frames: 9-10 iterations instead of 18-30; a wall view's finest level
// 3 instead of 6). A
// level ends at the first pose whose step is below tol; at the last level
// that pose is the answer, with its own figures. Flat components make this a
// point-to-plane cost near the surface and a point-to-point one at edges; the
// outlier term bounds the influence of points the target does not explain
// (its responsibility goes to the uniform term, not to a far component).
// With use_gray, each component scores the point's gray by its gray marginal
// and its position by the conditional N(x; mu_x|g, Sigma_x|g): the 4-D joint
// density, as colored ICP adds the photometric term.
// With depth_noise k, a point p of the source (in its sensor's frame) adds
// u u^T, u = k z R p, to each component's (conditional) spatial covariance:
// its depth error sigma_z = k z^2 along its ray (RegistrationOptions). u
// turns with the pose but is held at the current rotation within a step, as
// a model source's covariances are: the answer is that fixed point.
//
// Coarse to fine: `levels` levels smooth the target by s = coarse_sigma,
// coarse_sigma / 2, ..., and the last level by 0 (the model itself), so a
// start a few centimetres off still sees the surface; the smooth coarse
// levels use every 16th and 4th point. Each point tests only
// the components whose 3-sigma box (ComponentIndex) holds it.
//
// What comes back. The pose; the mean log-likelihood, the inlier ratio (a
// point is an inlier when the mixture explains it better than the outlier
// term) and the Mahalanobis RMS of the inliers; the 6 x 6 observed
// information (the negative Hessian of the log-likelihood at the pose, by
// Louis' identity: sum_ik w_ik J^T P_k J minus the covariance of the
// per-component gradients), which is near zero along directions the scene
// does not constrain (a plane slides in itself) even though every component
// alone would constrain them; and a status: Converged, or why not.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "sogmm/gmm.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// How register_points() runs (the option registry's REGISTRATION_* rows).
struct RegistrationOptions {
  /// Steps per level (each scores the level's source points once), >= 1.
  std::int32_t max_iter = 30;
  /// A level ends when a step moves the source by less than this (metres:
  /// |translation| + |rotation| x the source's RMS radius). > 0.
  double tol = 1e-4;
  /// eps: prior weight of the uniform outlier term, in [0, 1).
  double outlier_ratio = 0.1;
  /// true: score gray too (the 4-D joint density); false: the 3-D marginal.
  /// On by default: on the shared living-room pairs gray recovered 95 of 100
  /// starts up to 25 cm / 25 degrees off against 89 without (100 of 100 both
  /// up to 10 cm / 10 degrees, no false success either way) in 16-17 instead
  /// of 22-23 iterations, and tracking the synthetic loop needs it (a view
  /// along a textured wall slides under geometry alone: 212 of 300 frames
  /// inserted without gray, 300 with; README, Registration).
  bool use_gray = true;
  /// Coarse-to-fine levels, >= 1; the last one uses the model unsmoothed.
  std::int32_t levels = 3;
  /// Smoothing standard deviation of the coarsest level (metres), > 0.
  double coarse_sigma = 0.04;
  /// Below this inlier ratio at the end the status is LowFitness. [0, 1].
  double min_inlier_ratio = 0.5;
  /// A direction of the information matrix (rotations scaled by the source's
  /// RMS radius) whose eigenvalue is below this fraction of the largest one
  /// is unobservable; any such direction makes the status Degenerate. [0, 1).
  double degeneracy_ratio = 1e-3;
  /// Fewer finite source points than this: Error(InvalidData). >= 6.
  std::int64_t min_points = 100;
  /// k of the source's depth noise sigma_z = k z^2 (1/m; z a point's depth,
  /// its third coordinate in the sensor's frame, which the source points are
  /// in): each point p is scored under N(x; mu_k, Sigma_k + u u^T) with
  /// u = k z R p, its depth error moved along its ray into the target frame,
  /// as D2D adds a source component's covariance. A disparity-based sensor's
  /// error grows as z^2; the target's components, fitted to one frame's
  /// points, are thinner than the noise where it is correlated over a
  /// component (quantisation steps). [0, 1]; 0: off. Point sources only (a
  /// model source's covariances hold its noise already). A point's
  /// candidate components are still those whose 3-sigma box holds it. Off by
  /// default: it
  /// is the sensor's, and modelling noise a sensor does not have costs
  /// accuracy (the synthetic loop, depth exact to the millimetre, tracked
  /// with 0.001: ATE 0.80 against 0.58 cm); 0.001 suits the shared
  /// living-room frames (README, Registration).
  double depth_noise = 0.0;
};

/// Throws Error(InvalidArgument) naming the first bad setting.
void validate(const RegistrationOptions& options);

/// How a registration ended. Values are stable (sogmm.h SOGMM_REGISTRATION_*).
enum class RegistrationStatus : std::int32_t {
  Converged = 0,     ///< the last level's steps fell below tol; fitness and observability acceptable
  NotConverged = 1,  ///< the last level hit max_iter
  LowFitness = 2,    ///< converged, but the inlier ratio is below min_inlier_ratio
  Degenerate = 3,    ///< converged, but some directions are unobservable (see `unobservable`)
};

struct RegistrationResult {
  /// Row-major 4 x 4 rigid transform taking source points into the target's
  /// frame (x_target = R p + t): the last iterate, whatever the status.
  std::array<double, 16> pose{};
  RegistrationStatus status = RegistrationStatus::NotConverged;
  /// Iterations run, summed over the levels.
  std::int32_t iterations = 0;
  /// Mean log-likelihood per source point at the pose (the unsmoothed
  /// model with its outlier term; nats, 3-D or 4-D as use_gray).
  double log_likelihood = 0.0;
  /// Fraction of source points the mixture explains better than the outlier term.
  double inlier_ratio = 0.0;
  /// sqrt of the mean over inliers of sum_k w_k (x - mu_k)^T P_k (x - mu_k) / 3:
  /// about 1 for points spread as the model says.
  double rmse = 0.0;
  /// Observed information, row-major 6 x 6, over a left perturbation of the
  /// pose in the target frame: x -> x + w x x + v with xi = (w_x, w_y, w_z,
  /// v_x, v_y, v_z) (radians, metres); its inverse approximates the pose's
  /// covariance where it is invertible.
  std::array<double, 36> information{};
  /// Number of unobservable directions (0 to 6; see degeneracy_ratio).
  std::int32_t unobservable = 0;
  /// Smallest over largest eigenvalue of the scaled information (0 when the
  /// largest is 0): how close the scene is to degenerate.
  double eigen_ratio = 0.0;
};

/// Registers `n` source points (`points`: rows of x, y, z, gray float32)
/// to `target`, starting at `init` (row-major 4 x 4 rigid transform, source
/// to target frame). `threads` as QueryOptions::threads (the result does not
/// depend on it). `progress` receives Stage::Registration reports (step =
/// iterations done, total = levels x max_iter, the mean log-likelihood) and
/// may cancel. Errors: an invalid target or bad options ->
/// Error(InvalidArgument/InvalidData); a non-rigid or non-finite `init` ->
/// Error(InvalidArgument) saying what is wrong; a non-finite point ->
/// Error(InvalidData) naming its row; fewer than min_points points ->
/// Error(InvalidData).
RegistrationResult register_points(const Gmm& target, const float* points, std::size_t n,
                                   const std::array<double, 16>& init, const RegistrationOptions& options = {},
                                   int threads = 0, const ProgressSink& progress = {});

/// Registers a fitted model `source` to `target` (distribution to
/// distribution, D2D), starting at `init` (source to target frame, as in
/// register_points). Each source component j is scored as a point at its
/// transformed mean whose density under target component k is the closed
/// form of the Gaussian overlap, N(R m_j + t; mu_k, Sigma_k + diag(R, 1)
/// S_j diag(R, 1)^T) (4-D with use_gray, the spatial marginal otherwise),
/// counted pi_j x support_size times (the points it stands for; a
/// support_size of 0 is taken as the number of components), with the same
/// outlier term, coarse-to-fine levels, Gauss-Newton steps, figures and
/// status as register_points. Each step holds the source covariances at the
/// current rotation (the change of log det(Sigma_k + R S_j R^T) with R is
/// not followed), so the pose returned is a fixed point of that step, as in
/// GICP, not exactly the maximum of the overlap objective; the log-likelihood and inlier ratio are per point stood
/// for. A frame's fit registers in a fraction of its points' time: its
/// components are few. Errors: as register_points for the target, options
/// and init; a source without components, or standing for fewer than
/// min_points points -> Error(InvalidData); an invalid source -> validate()'s
/// error.
RegistrationResult register_model(const Gmm& target, const Gmm& source, const std::array<double, 16>& init,
                                  const RegistrationOptions& options = {}, int threads = 0,
                                  const ProgressSink& progress = {});

/// A target prepared once for many registrations, as when frames are
/// localised one after another in a fixed map. A call against a Gmm first
/// validates it and builds each level's smoothed components, boxes and
/// index (about a fifth of a d = 5 frame's CPU against a 3,000-component
/// map); a RegistrationTarget holds them, so its calls skip that work.
/// Its answers are bit-identical to the calls against the Gmm it was made
/// from, with the same options. It copies what it needs (the Gmm may change
/// or go afterwards), is immutable, and may be shared by threads. Memory:
/// about half a kilobyte per component and level. A moved-from target may
/// only be assigned to or destroyed. Its preparation runs before any
/// registration's progress scope, so it is not cancellable.
class RegistrationTarget {
 public:
  /// Validates `target` and `options` and prepares the levels that
  /// `options` (levels, coarse_sigma, outlier_ratio, use_gray) ask for, on
  /// `threads` (QueryOptions::threads). Errors: those of register_points
  /// for the target and options.
  RegistrationTarget(const Gmm& target, const RegistrationOptions& options, int threads = 0);
  ~RegistrationTarget();
  RegistrationTarget(RegistrationTarget&&) noexcept;
  RegistrationTarget& operator=(RegistrationTarget&&) noexcept;

  /// True when a registration with `options` can use this preparation: the
  /// same levels, coarse_sigma, outlier_ratio and use_gray. The other options
  /// (iterations, tolerances, thresholds) may differ.
  bool prepared_for(const RegistrationOptions& options) const;

  struct Prepared;  ///< the levels (registration.cpp)
  const Prepared& prepared() const { return *prepared_; }

 private:
  std::unique_ptr<const Prepared> prepared_;
};

/// register_points against a prepared target. Errors: as register_points;
/// options that the target was not prepared_for -> Error(InvalidArgument).
RegistrationResult register_points(const RegistrationTarget& target, const float* points, std::size_t n,
                                   const std::array<double, 16>& init, const RegistrationOptions& options = {},
                                   int threads = 0, const ProgressSink& progress = {});

/// register_model against a prepared target. Errors: as register_model;
/// options that the target was not prepared_for -> Error(InvalidArgument).
RegistrationResult register_model(const RegistrationTarget& target, const Gmm& source,
                                  const std::array<double, 16>& init, const RegistrationOptions& options = {},
                                  int threads = 0, const ProgressSink& progress = {});

/// Name of a status ("converged", "not converged", "low fitness", "degenerate").
const char* status_name(RegistrationStatus status);

}  // namespace sogmm
