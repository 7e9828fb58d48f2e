// A small NDT-map (normal distributions transform) for `sogmm bench`: one 3-D
// Gaussian per occupied voxel plus the mean gray of the voxel's points, the
// baseline the paper builds by adding gray to perception_oru's NDTCell.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "sogmm/point_cloud.hpp"

namespace sogmm::bench {

/// One occupied voxel.
struct NdtCell {
  std::int64_t ix = 0, iy = 0, iz = 0;  ///< voxel index: floor(coordinate / voxel size)
  std::size_t count = 0;                ///< number of points in the voxel
  double mean[3] = {0, 0, 0};           ///< mean of the points (m)
  double cov[6] = {0, 0, 0, 0, 0, 0};   ///< ML covariance, upper triangle xx xy xz yy yz zz
  double gray = 0.0;                    ///< exact mean gray of the points
  /// Sampling factor A with cov_reg = A A^T (row-major 3x3), after the
  /// eigenvalue floor (see NdtMap).
  double factor[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
};

/// Voxel grid of Gaussians. Covariances are the maximum-likelihood ones of the
/// voxel's points; as in NDT implementations, eigenvalues smaller than
/// max eigenvalue / 100 are raised to that value before sampling (so planar
/// voxels keep a thin, non-degenerate thickness). A voxel with one point has a
/// zero covariance and samples at that point.
class NdtMap {
 public:
  /// Throws Error(InvalidArgument) unless voxel > 0 and finite.
  explicit NdtMap(double voxel);

  /// Adds the points (x, y, z, gray) of a cloud and recomputes every cell.
  /// Throws Error(InvalidData) for NaN/Inf or coordinates beyond the voxel
  /// index range (about +-1e6 voxels).
  void build(const PointsView& points);

  double voxel() const { return voxel_; }
  /// Number of occupied voxels M.
  std::size_t size() const { return cells_.size(); }
  const std::vector<NdtCell>& cells() const { return cells_; }

  /// Bytes as the paper counts them: 4 M (1 + 3 + 6) (gray, mean, covariance).
  std::size_t paper_bytes() const { return 4 * size() * (1 + 3 + 6); }

  /// Gray at a 3-D point: the mean gray of the voxel containing it, or, when
  /// that voxel is empty, of the occupied voxel whose centre is nearest.
  /// `used_fallback` (if not null) is incremented when the fallback is used.
  float gray_at(const float* xyz, std::size_t* used_fallback = nullptr) const;

  /// `n` points (rows of 3 floats) drawn from the cells' Gaussians, cell c
  /// getting a share of n proportional to its point count (largest-remainder
  /// rounding, so n = number of input points gives each cell exactly its
  /// count). Each draw is mean + A z with z standard normal, every coordinate
  /// redrawn until |z_i| < 2.5 (as the GMM sampler). Deterministic in `seed`.
  std::vector<float> sample(std::size_t n, std::uint64_t seed) const;

 private:
  std::int64_t key_of(std::int64_t ix, std::int64_t iy, std::int64_t iz) const;
  double voxel_;
  std::vector<NdtCell> cells_;
  std::unordered_map<std::int64_t, std::size_t> index_;
  // Raw sums for incremental builds.
  struct Sums {
    double s[3] = {0, 0, 0};
    double ss[6] = {0, 0, 0, 0, 0, 0};
    double g = 0;
  };
  std::vector<Sums> sums_;
};

/// Number of draws per bucket for `n` draws in proportion to `counts`
/// (largest-remainder rounding, ties to the lower index). Sums to n.
std::vector<std::size_t> proportional_allocation(const std::vector<std::size_t>& counts, std::size_t n);

}  // namespace sogmm::bench
