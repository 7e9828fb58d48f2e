// The whole SOGMM fit of one point cloud: mode count -> k-means++ -> EM.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sogmm/em.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/mean_shift.hpp"
#include "sogmm/point_cloud.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// Resource limits of a fit. A fit refuses larger inputs up front with
/// Error(ErrorCode::Limit) (the C API's SOGMM_E_LIMIT) instead of running out
/// of memory or time:
/// - kMaxPoints: at most 2^26 (67,108,864) points per fit (1 GiB of float32
///   input; internal point indices are 32-bit).
/// - kMaxComponents: at most 2^16 (65,536) components, whether requested as a
///   fixed K or counted by the mode counter (a bandwidth so small that it finds
///   more modes is refused; use a larger bandwidth).
inline constexpr std::size_t kMaxPoints = std::size_t{1} << 26;
inline constexpr std::size_t kMaxComponents = std::size_t{1} << 16;

/// How the number of components is chosen.
enum class ModeCounter {
  FlatBinned,        ///< flat-kernel mean shift with bin seeding (authors' code; default)
  GaussianBlurring,  ///< Gaussian blurring mean shift (the paper's description)
};

/// Parameters of a fit. Set `n_components` > 0 for the fixed-K baseline
/// (the paper's FC), which skips the mode count.
/// FitOptions::dequantise_depth. The values are the C API's
/// (SOGMM_OPT_DEQUANTISE_DEPTH: SOGMM_DEQUANTISE_AUTO, 0, 1).
enum class Dequantise : int {
  Auto = -1,  ///< on for points from a depth image, off otherwise
  Off = 0,    ///< the paper's plain EM
  On = 1,     ///< floor whenever the camera-frame depth is quantised
};

struct FitOptions {
  double bandwidth = 0.02;          ///< mean-shift bandwidth sigma (the one SOGMM parameter)
  std::size_t n_components = 0;     ///< 0 = self-organizing; K > 0 = fixed-K fit
  ModeCounter mode_counter = ModeCounter::FlatBinned;
  MeanShiftOptions mean_shift;      ///< flat mean-shift details
  std::uint64_t seed = 0;           ///< seeds k-means++; same seed, same model
  /// Number of runs (k-means++ then EM), in [1, kMaxRuns]. Run r (from 0)
  /// seeds k-means++ with `seed + r` (wrapping); the run with the highest
  /// final mean log-likelihood is kept (ties: the earliest). 1 (default) is
  /// the paper's single run. EM results vary by a few hundredths of a nat
  /// per point from seed to seed, so a few runs buy a better optimum at a
  /// proportional cost (scikit-learn's GaussianMixture(n_init)).
  int n_init = 1;
  /// The depth-quantisation floor. Depth from a 16-bit image sits on
  /// discrete levels (the shared livingroom frames: 191 levels, 4 mm apart at
  /// 1 m); plain EM then folds components onto single levels one by one,
  /// which raises the training likelihood without bound and converges slowly
  /// (3 of 10 seeds within 100 iterations at d = 2). With the floor, when the
  /// camera-frame depth is detected as quantised (DepthQuantisation::detect
  /// measures the levels themselves, so a step that grows with range is
  /// followed), every M-step floors each component's variance along its
  /// viewing ray at the level's bin variance: every seed converges and the
  /// likelihood of held-out pixels, their depths spread over their bins, is
  /// higher (README, "Depth quantisation").
  /// Auto (default): on for points back-projected from a depth image
  /// (PointsView::from_depth_image), off for points given without a camera.
  Dequantise dequantise_depth = Dequantise::Auto;
  EmOptions em;                     ///< EM tolerances and threads
};

/// Whether the depth floor applies to these points under these options.
bool dequantises(Dequantise setting, const PointsView& points);

/// Upper bound of FitOptions::n_init.
inline constexpr int kMaxRuns = 1000;

/// A fitted model and how it was obtained.
struct FitResult {
  Gmm gmm;
  EmReport em;                     ///< the EM of the kept run
  int run = 0;                     ///< which run was kept (from 0; its seed is seed + run)
  std::vector<double> run_log_likelihoods;  ///< final mean log-likelihood of every run
  std::size_t n_points = 0;
  double seconds_mode_count = 0.0;
  double seconds_seeding = 0.0;    ///< summed over runs
  double seconds_em = 0.0;         ///< summed over runs
  double seconds_total = 0.0;
};

/// Fits a SOGMM (or a fixed-K GMM) to a cloud in the camera frame. Throws
/// Error(Limit) for N > kMaxPoints or K > kMaxComponents (checked before the
/// points are read), Error(InvalidArgument) for bandwidth <= 0, K outside
/// [1, N] or n_init outside [1, kMaxRuns], Error(InvalidData) for an empty or non-finite cloud, Error(Numeric)
/// if the result fails validation, Error(Cancelled) when a progress sink
/// cancels. `progress` (may be empty) is installed as a ProgressScope for the
/// call: stages ModeCount (skipped for a fixed K), then per run Run (only when
/// n_init > 1), Seeding and Em, whose log-likelihood after each iteration is
/// that iteration's E-step mean. The result does not depend on the sink.
FitResult fit(const PointsView& points, const FitOptions& options, const ProgressSink& progress = {});

/// The modes that fit() counts for `points` (its first stage, the number of
/// components of a self-organizing fit): mean shift over the (range, gray)
/// features with options.bandwidth, by options.mode_counter and
/// options.mean_shift, on the calling thread's OpenMP team (fit() sets it to
/// options.em.threads). Throws as the mean shift for an unusable bandwidth.
MeanShiftResult count_modes(const PointsView& points, const FitOptions& options);

}  // namespace sogmm
