// Model invariants: the one place that decides whether a Gmm is usable.
#include "sogmm/gmm.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Core>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm {

std::string validation_error(const Gmm& gmm, double weight_tolerance) {
  const std::size_t m = gmm.weights.size();
  std::ostringstream msg;
  if (m == 0) return "model has no components (M = 0)";
  if (gmm.means.size() != 4 * m || gmm.covariances.size() != 16 * m) {
    msg << "array lengths disagree with M = " << m << ": " << gmm.means.size() << " mean values (expected "
        << 4 * m << "), " << gmm.covariances.size() << " covariance values (expected " << 16 * m << ")";
    return msg.str();
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const float w = gmm.weights[k];
    if (!std::isfinite(w) || w < 0.0f) {
      msg << "component " << k << " has an invalid weight " << checked::exact(w);
      return msg.str();
    }
    sum += w;
  }
  if (std::fabs(sum - 1.0) > weight_tolerance) {
    msg << "weights sum to " << checked::exact(sum) << ", not 1";
    return msg.str();
  }
  for (std::size_t k = 0; k < m; ++k) {
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(gmm.mean(k)[i])) {
        msg << "component " << k << " has a non-finite mean";
        return msg.str();
      }
    }
    Eigen::Matrix4d c = Eigen::Map<const Eigen::Matrix<float, 4, 4, Eigen::RowMajor>>(gmm.covariance(k)).cast<double>();
    if (!c.allFinite()) {
      msg << "component " << k << " has a non-finite covariance";
      return msg.str();
    }
    const double scale = c.cwiseAbs().maxCoeff();
    if ((c - c.transpose()).cwiseAbs().maxCoeff() > 1e-5 * scale) {
      msg << "component " << k << " has a non-symmetric covariance";
      return msg.str();
    }
    // Positive definite as stored in a file: the symmetric part, each entry
    // (a_ij + a_ji) / 2 rounded to float32, is what a reader returns and what
    // the writer checks (spec/format.md 5.1), with the same test, so a model
    // that passes here can always be saved. The lower triangle alone is not
    // enough: a matrix asymmetric within the tolerance above could pass on it
    // while its symmetric part is not positive definite (found by fuzz_api:
    // c22 = 4.7e-41, c23 = 2.6e-9, c32 = 0). For a symmetric matrix, every
    // model the library makes, the symmetric part is the matrix itself.
    double sym[16];
    stored_symmetric_part(gmm.covariance(k), sym);
    if (!stored_cholesky(sym)) {
      msg << "component " << k << " has a covariance that is not positive definite";
      return msg.str();
    }
  }
  return {};
}

void validate(const Gmm& gmm, double weight_tolerance) {
  const std::string error = validation_error(gmm, weight_tolerance);
  if (!error.empty()) {
    const bool structural = gmm.weights.empty() || error.rfind("array lengths", 0) == 0;
    throw Error(structural ? ErrorCode::InvalidData : ErrorCode::Numeric, "invalid model: " + error);
  }
}

}  // namespace sogmm
