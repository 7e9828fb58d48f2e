// Argument checks shared by the C API translation units.
#include <cmath>
#include <string>

#include "internal.hpp"

namespace sogmm_capi {

void require_finite(const float* values, std::size_t count, const char* what) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i]))
      fail(SOGMM_E_INVALID_DATA, std::string(what) + ": value at index " + std::to_string(i) +
                                     " is not finite");
  }
}

void require_rigid(const double* p, const char* what) {
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(p[i]))
      fail(SOGMM_E_INVALID_ARG, std::string(what) + ": entry " + std::to_string(i) + " is not finite");
  }
  const double tol = 1e-4;
  if (std::fabs(p[12]) > tol || std::fabs(p[13]) > tol || std::fabs(p[14]) > tol ||
      std::fabs(p[15] - 1.0) > tol)
    fail(SOGMM_E_INVALID_ARG, std::string(what) + ": last row is not (0, 0, 0, 1)");
  // R^T R = I within tol.
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      double dot = 0.0;
      for (int r = 0; r < 3; ++r) dot += p[4 * r + a] * p[4 * r + b];
      if (std::fabs(dot - (a == b ? 1.0 : 0.0)) > tol)
        fail(SOGMM_E_INVALID_ARG, std::string(what) + ": rotation block is not orthonormal");
    }
  }
  const double det = p[0] * (p[5] * p[10] - p[6] * p[9]) - p[1] * (p[4] * p[10] - p[6] * p[8]) +
                     p[2] * (p[4] * p[9] - p[5] * p[8]);
  if (std::fabs(det - 1.0) > tol)
    fail(SOGMM_E_INVALID_ARG, std::string(what) + ": rotation block has determinant " +
                                  std::to_string(det) + ", not 1 (a reflection?)");
}

}  // namespace sogmm_capi
