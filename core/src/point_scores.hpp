// One exact E-step of a given model over a cloud, with the float32 EM kernels
// (private to the core): what the warm start needs to decide which components
// to keep and which points are new.
#pragma once

#include <cstddef>
#include <vector>

#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm::detail {

/// Per point and per component results of one E-step.
struct PointScores {
  std::vector<double> log_likelihood;  ///< N: log p(x_i) under the model
  std::vector<double> mass;            ///< M: sum over the counted points of component k's responsibility
};

/// Scores every point against every component (the EM's exact E-step, float32
/// kernels relative to the midpoint of the cloud's bounding box, so accuracy
/// does not depend on the cloud's offset). Partial masses are summed over 16
/// fixed chunks in chunk order, so the result is the same for any `threads`.
/// `counted` (N flags) selects the points whose responsibilities enter the
/// masses; null counts every point. The model must be valid (validate()) and
/// the points finite.
PointScores score_points(const PointsView& points, const Gmm& gmm, int threads,
                         const std::vector<char>* counted = nullptr);

}  // namespace sogmm::detail
