// Depth quantisation of a camera-frame cloud, and the covariance it adds.
#pragma once

#include <cstddef>
#include <vector>

#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// The distinct depths of a camera-frame cloud whose depth sensor quantises
/// depth (a Kinect-style sensor stores disparity: on the shared livingroom
/// frames 191 levels 4 mm apart at 1 m and 16 mm at 2 m hold 67k points).
/// A point's true depth lies anywhere in the bin around its level, yet a
/// Gaussian can put its thin axis on one level: the likelihood then rises
/// without bound (up to reg_covar) as ever more components collapse onto
/// single levels, one per iteration, so EM crawls (issue 14 item 10). A
/// component cannot know the depth better than its bin, so its variance along
/// the viewing ray is floored at the bin's uniform variance; that stops the
/// collapse. (Adding the bin's variance to every component, the EM of the
/// dequantised depths, stops it too and scores higher on dequantised data,
/// but it blurs every surface by the bin and moves the d = 5 F-score against
/// the quantised ground truth out of its seed spread: 0.463 against 0.492.)
class DepthQuantisation {
 public:
  /// No quantisation: covariance_at() adds nothing.
  DepthQuantisation() = default;

  /// Detects quantised depth: every z > 0 (the camera frame, points in front
  /// of the camera) and at least kMinPointsPerLevel points per distinct z on
  /// average. Continuous depths (about one point per value) and clouds that
  /// are not in a camera frame give no quantisation.
  static DepthQuantisation detect(const PointsView& points);

  /// Average number of points per distinct depth from which depth counts as
  /// quantised (the shared frames have 60 at d = 5 and 350 at d = 2; a
  /// continuous float32 cloud has about 1).
  static constexpr std::size_t kMinPointsPerLevel = 8;

  bool empty() const { return levels_.size() < 2; }

  /// Floors the variance along the viewing ray of the row-major 4 x 4
  /// `covariance` of a component whose mean is `mean` (x, y, z, gray, camera
  /// frame) at the variance of a uniform error over the depth bin at mean z:
  /// with v = (x/z, y/z, 1), u = v / |v| and w the spacing of the two levels
  /// around z (the nearest spacing beyond the outermost levels), the bin's
  /// variance along u is s = |v|^2 w^2 / 12; when u^T C u < s, C gains
  /// (s - u^T C u) u u^T (the least change that reaches it). Nothing when
  /// empty() or mean z <= 0.
  void floor_covariance_at(const double mean[4], double covariance[16]) const;

 private:
  std::vector<double> levels_;  // sorted distinct depths
};

}  // namespace sogmm
