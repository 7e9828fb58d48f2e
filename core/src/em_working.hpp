// The EM's working model (private to the EM: em.cpp and em_acceleration.cpp).
#pragma once

#include <cstddef>
#include <vector>

namespace sogmm::detail {

// Components per claim of the EM's per-component parallel loops (M-step,
// Cholesky packing, SQUAREM's step length and load check): a component's
// work takes about a microsecond, so a claim is worth a thread's hand-off.
constexpr std::size_t kComponentsPerClaim = 64;

// The fit's working model, in double and relative to the frame's origin:
// float32 means would round every update to the float grid at the data's
// offset (1 mm at 10 km), and float32 covariances cannot hold a thin
// component of a large scene. float32 is only the kernels' and the storage's
// type.
struct Working {
  std::vector<double> mean;        // M x 4, relative to the fit's origin
  std::vector<double> covariance;  // M x 16, row-major
  std::vector<double> log_weight;  // M
  std::size_t size() const { return log_weight.size(); }
};

}  // namespace sogmm::detail
