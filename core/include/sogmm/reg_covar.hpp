// The covariance regulariser of the EM: the user's value, or floors derived
// from the data's spatial and gray scales.
#pragma once

#include <optional>

#include "sogmm/point_cloud.hpp"

namespace sogmm {

struct Model;

/// What the EM adds to the covariance diagonals in every M-step (and the
/// seeds' covariances): `spatial` on x, y and z, `gray` on gray.
struct RegCovarFloors {
  double spatial = 1e-6;   ///< data units squared (m^2)
  double gray = 1e-6;      ///< gray units squared
  bool automatic = false;  ///< derived from the data (auto_reg_covar), not given by the user
};

/// The floors derived from the data's scales, each a power of ten, so that
/// a cloud scaled by 10 gets floors exactly 100 times larger:
/// - spatial = 1e-6 x 100^k, where 10^k is the power of ten nearest (on a log
///   scale) the median distance of the points (x, y, z) from their
///   coordinate-wise median. The paper's 1e-6 m^2 at room scale: the shared
///   room frames measure 0.79-0.95 m (k = 0); a 1 km plane gets 1 m^2.
///   A typical size rather than the extent, so that a far outlier does not
///   move it.
/// - gray = 1e-6 x 100^k, where 10^k is the smallest power of ten not below
///   the gray range (a range up to 1e-6 above a power of ten, float
///   rounding, counts as that power). The range is the spread between the
///   gray quantiles 1% and 99% (order statistics floor(0.01 (N - 1)) from
///   each end; max - min below 101 points), so that out-of-range pixels, up
///   to 1% at each end, do not set the floor of every component; when that
///   spread is 0 (more than 98% of the points share one gray), max - min.
///   Gray's resolution follows its unit, not its
///   spread (8-bit gray in [0, 1] keeps 1e-6, about its quantisation
///   variance (1/255)^2 / 12, also for a dark or low-contrast frame; in
///   [0, 255] it gets 1).
/// A zero size (more than half of the points at one place; constant gray)
/// falls back to the largest side of the xyz bounding box, then to k = 0.
/// The floors are clamped to [1e-36, 1e36] (finite, normal float32 values).
/// O(N) time and N floats of scratch. `points` must be non-empty and finite.
RegCovarFloors auto_reg_covar(const PointsView& points);

/// `reg_covar` on all four diagonals when the user set it (automatic =
/// false), else auto_reg_covar(points). Throws Error(InvalidArgument) for a
/// value that is negative, NaN or infinite.
RegCovarFloors resolve_reg_covar(const PointsView& points, const std::optional<double>& reg_covar);

/// Key of Model::key_values with the gray floor the fit used (round-trip
/// decimal; FitInfo::reg_covar holds the spatial one), spec/format.md 2.4.
inline constexpr const char* kRegCovarGrayKey = "reg_covar_gray";
/// Key of Model::key_values saying where the floors came from: "auto"
/// (auto_reg_covar) or "user" (one value on all four diagonals).
inline constexpr const char* kRegCovarSourceKey = "reg_covar_source";

/// Records the floors a fit used in `model`: FitInfo::reg_covar = spatial and
/// the two keys above. The one place every fit record (C API, CLI, map,
/// benchmarks) takes them from.
void record_reg_covar(Model& model, const RegCovarFloors& floors);

}  // namespace sogmm
