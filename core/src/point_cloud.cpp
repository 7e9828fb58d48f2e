#include "sogmm/point_cloud.hpp"

#include <cmath>
#include <string>

#include "sogmm/error.hpp"

namespace sogmm {

void require_finite_points(const PointsView& points, const char* what) {
  require(points.size > 0 && points.data != nullptr, ErrorCode::InvalidData, std::string(what) + " is empty");
  const std::size_t n = 4 * points.size;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(points.data[i])) {
      throw Error(ErrorCode::InvalidData, std::string(what) + " has a non-finite value (NaN or Inf) at point " +
                                              std::to_string(i / 4) + ", coordinate " + std::to_string(i % 4));
    }
  }
}

}  // namespace sogmm
