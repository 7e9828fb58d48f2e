// Argument checks shared by the C API translation units.
#include <algorithm>
#include <cmath>
#include <string>

#include "internal.hpp"
#include "sogmm/checked.hpp"

namespace sogmm_capi {

void require_finite(const float* values, std::size_t count, const char* what) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i]))
      fail(SOGMM_E_INVALID_DATA, std::string(what) + ": value at index " + std::to_string(i) + " is " +
                                     sogmm::checked::exact(values[i]) + ", not finite");
  }
}

std::array<double, 16> require_rigid(const double* p, const char* what) {
  std::array<double, 16> pose;
  std::copy(p, p + 16, pose.begin());
  const std::string problem = sogmm::rigid_pose_error(pose);
  if (!problem.empty()) fail(SOGMM_E_INVALID_ARG, std::string(what) + ": " + problem);
  return pose;
}

}  // namespace sogmm_capi
