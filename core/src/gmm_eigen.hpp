// A Gmm's components as Eigen matrices in double, and a checked Cholesky
// factorisation (private to the core: inference.cpp, query.cpp, point_scores.cpp).
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "sogmm/error.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm::detail {

/// Component k's covariance, in double: its symmetric part, each entry
/// (a_ij + a_ji) / 2 rounded to float32, which is what validate() tests and a
/// file holds (the matrix itself for every model the library makes; a model
/// given as arrays may be asymmetric within validate's tolerance).
inline Eigen::Matrix4d covariance_of(const Gmm& gmm, std::size_t k) {
  double s[16];
  stored_symmetric_part(gmm.covariance(k), s);
  return Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(s);
}
/// Component k's mean, in double.
inline Eigen::Vector4d mean_of(const Gmm& gmm, std::size_t k) {
  return Eigen::Map<const Eigen::Vector4f>(gmm.mean(k)).cast<double>();
}

/// Component k's Cholesky factor L (covariance = L L^T) by the test validate()
/// makes (stored_cholesky): every valid model can be scored, sampled and
/// queried, even one whose nearly singular covariance another factorisation
/// would round to a zero pivot. Its top-left 3 x 3 block is the factor of the
/// spatial covariance (the same arithmetic on the same entries). Throws
/// Error(Numeric) for a model that was never validated and is not positive
/// definite.
/// `c` is covariance_of(gmm, k), passed in by a caller that needs it too.
inline Eigen::Matrix4d cholesky_of(const Eigen::Matrix4d& c, std::size_t k) {
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> a = c;
  double l[16];
  if (!stored_cholesky(a.data(), l))
    throw Error(ErrorCode::Numeric, "covariance of component " + std::to_string(k) + " is not positive definite");
  return Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(l);
}
/// The same for component k of `gmm`.
inline Eigen::Matrix4d cholesky_of(const Gmm& gmm, std::size_t k) { return cholesky_of(covariance_of(gmm, k), k); }

/// The Cholesky factorisation of a covariance (or a block of one), checked:
/// validate() accepts the float32 model, yet a sub-block or a derived matrix
/// could still fail in double, and an unchecked failure would turn into NaN
/// answers silently. Throws Error(Numeric) naming `what` and component `k`
/// (none when k is -1).
template <class M>
Eigen::LLT<M> checked_llt(const M& c, const char* what, std::size_t k = static_cast<std::size_t>(-1)) {
  Eigen::LLT<M> llt(c);
  if (llt.info() != Eigen::Success)
    throw Error(ErrorCode::Numeric, std::string(what) +
                                        (k == static_cast<std::size_t>(-1) ? "" : " of component " + std::to_string(k)) +
                                        " is not positive definite");
  return llt;
}

}  // namespace sogmm::detail
