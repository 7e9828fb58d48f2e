// Mode counting: how many Gaussian components a frame needs (the paper's PRI step).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// Where the bin-seeding grid is anchored.
enum class BinAnchor {
  DataMin,  ///< cell index floor((v - min) / sigma + 0.5): the authors' code (default)
  Zero,     ///< cell index round-half-even(v / sigma): scikit-learn's get_bin_seeds
};

/// Options of the flat-kernel mean shift.
struct MeanShiftOptions {
  BinAnchor anchor = BinAnchor::DataMin;
  int max_iter = 300;         ///< steps per seed
  double stop_fraction = 1e-3;  ///< a seed stops when it moves <= stop_fraction * bandwidth
};

/// Result of a mean shift: the kept modes, strongest first.
struct MeanShiftResult {
  std::vector<double> centers;        ///< K x 2 row-major
  std::vector<std::size_t> strengths; ///< points within bandwidth of each centre
  /// Cost of the run: the points each neighbour query examined one by one
  /// (including duplicate suppression's), i.e. those of the grid cells whose
  /// bounds the query's disc reaches without containing them, plus, for the
  /// flat mean shift, one per run of cells it took whole. Deterministic and
  /// independent of the thread count, so tests can bound cost without a clock.
  std::uint64_t neighbour_checks = 0;
  std::size_t size() const { return strengths.size(); }
};

/// True when `bandwidth` can be used as a mean-shift (and Gaussian kernel)
/// scale: finite, > 0, and bandwidth^2, (3 bandwidth)^2 (the blurring kernel's
/// radius) and 1 / (2 bandwidth^2) finite and non-zero, i.e. roughly
/// 5.3e-155 < bandwidth < 4.4e153. Outside that the kernel
/// weights are 0 * inf = NaN. The C API's option setter applies the same rule.
bool bandwidth_is_usable(double bandwidth);

/// Throws Error(InvalidArgument) naming the exact value unless bandwidth_is_usable.
void require_usable_bandwidth(double bandwidth);

/// Throws Error(Limit) naming the axis and bandwidth when the mode count
/// cannot index the 2-D features (range, gray) of `points2d` (N x 2,
/// row-major, finite) at `bandwidth`: an axis spanning more than 1e8
/// bandwidths, or a value beyond 1e15 bandwidths. Both mean shifts apply it;
/// the map applies it to a batch before accepting the insert that forms it.
void require_mode_count_range(const std::vector<double>& points2d, double bandwidth);

/// Flat-kernel mean shift with bin seeding on 2-D data (N x 2, row-major), as
/// scikit-learn's MeanShift(bin_seeding=True, min_bin_freq=1, cluster_all):
/// seeds are the centres of occupied grid cells of size `bandwidth`; each moves
/// to the mean of the points within distance `bandwidth` until it moves
/// <= 1e-3 bandwidth or after 300 steps; converged seeds are ordered by the
/// number of points within bandwidth (most first) and a seed within bandwidth
/// of an already kept one is dropped. Radius queries use a sparse grid of
/// cells a quarter bandwidth wide (only occupied cells and rows are stored)
/// that adds a run of cells wholly inside the disc as one difference of
/// running sums, so the cost does not depend on the bounding box (a far
/// outlier adds one cell and one mode) and most of a disc costs no per-point
/// test. The points counted are exactly those within the bandwidth; the order
/// of the additions is the grid's, fixed by the data and the query.
/// Runs in parallel over seeds; the result does not depend on the thread
/// count. Throws Error(InvalidArgument) for a bandwidth that is
/// not bandwidth_is_usable, Error(InvalidData) for empty or non-finite data.
MeanShiftResult mean_shift_flat(const std::vector<double>& points2d, double bandwidth,
                                const MeanShiftOptions& options = {});

/// Gaussian blurring mean shift (the variant the paper describes, Carreira-
/// Perpinan 2006): every point moves to the Gaussian-weighted mean of the
/// current (blurred) points, kernel truncated at 3 bandwidths; iterations stop
/// when the mean squared movement falls below (1e-3 bandwidth)^2 or after
/// `max_iter`. Points that end within bandwidth / 2 of each other form one
/// mode. Returns the modes, strongest first. O(iterations * N * neighbours).
MeanShiftResult mean_shift_gaussian_blurring(const std::vector<double>& points2d, double bandwidth,
                                             int max_iter = 100);

/// The 2-D features the mode count runs on: (range = |(x, y, z)|, gray) per
/// point, with range measured from the camera centre (the cloud must be in
/// the camera frame, as backproject() returns it).
std::vector<double> range_gray_features(const PointsView& points);

}  // namespace sogmm
