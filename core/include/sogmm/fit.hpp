// The whole SOGMM fit of one point cloud: mode count -> k-means++ -> EM.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "sogmm/em.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/mean_shift.hpp"
#include "sogmm/point_cloud.hpp"

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
struct FitOptions {
  double bandwidth = 0.02;          ///< mean-shift bandwidth sigma (the one SOGMM parameter)
  std::size_t n_components = 0;     ///< 0 = self-organizing; K > 0 = fixed-K fit
  ModeCounter mode_counter = ModeCounter::FlatBinned;
  MeanShiftOptions mean_shift;      ///< flat mean-shift details
  std::uint64_t seed = 0;           ///< seeds k-means++; same seed, same model
  EmOptions em;                     ///< EM tolerances and threads
};

/// Which stage a fit is in, for progress reports.
enum class FitStage { ModeCount, Seeding, Em };

/// Called at the start of each stage and after each EM iteration; may be
/// empty. ModeCount: (0, 0). Seeding: (K, 0), the number of components about
/// to be seeded. Em: (0, 0) at the start, then (iteration, mean
/// log-likelihood of that iteration's E-step) after each iteration.
using FitProgress = std::function<void(FitStage stage, int iteration, double log_likelihood)>;

/// A fitted model and how it was obtained.
struct FitResult {
  Gmm gmm;
  EmReport em;
  std::size_t n_points = 0;
  double seconds_mode_count = 0.0;
  double seconds_seeding = 0.0;
  double seconds_em = 0.0;
  double seconds_total = 0.0;
};

/// Fits a SOGMM (or a fixed-K GMM) to a cloud in the camera frame. Throws
/// Error(Limit) for N > kMaxPoints or K > kMaxComponents (checked before the
/// points are read), Error(InvalidArgument) for bandwidth <= 0 or K outside
/// [1, N], Error(InvalidData) for an empty or non-finite cloud, Error(Numeric)
/// if the result fails validation.
FitResult fit(const PointsView& points, const FitOptions& options, const FitProgress& progress = {});

}  // namespace sogmm
