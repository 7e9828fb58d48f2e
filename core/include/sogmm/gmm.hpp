// The 4-D Gaussian mixture over (x, y, z, gray) that every SOGMM stage produces.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sogmm {

/// Dimension of the joint model: x, y, z in metres, gray in [0, 1].
inline constexpr int kDims = 4;

/// A full-covariance Gaussian mixture in 4-D, stored as float32 (as the paper
/// counts it) in plain row-major arrays so that the C API, the file format and
/// bindings can copy them without conversion.
struct Gmm {
  std::vector<float> weights;      ///< M mixing weights, >= 0, summing to 1
  std::vector<float> means;        ///< M x 4 row-major, (x, y, z, gray)
  std::vector<float> covariances;  ///< M x 4 x 4 row-major, symmetric positive definite
  /// Number of points the model was fitted on (sum over merged models); the
  /// weight of this model when merged with another.
  std::uint64_t support_size = 0;

  /// Number of components M.
  std::size_t size() const { return weights.size(); }
  /// Pointer to the 4 coordinates of component m's mean.
  const float* mean(std::size_t m) const { return means.data() + 4 * m; }
  /// Pointer to the 16 row-major entries of component m's covariance.
  const float* covariance(std::size_t m) const { return covariances.data() + 16 * m; }
  /// Resizes all arrays to hold m components (contents unspecified).
  void resize(std::size_t m) {
    weights.resize(m);
    means.resize(4 * m);
    covariances.resize(16 * m);
  }
};

/// The library's one positive-definiteness test of a 4 x 4 covariance, step
/// 19d of spec/format.md exactly: a Cholesky-Banachiewicz factorisation in
/// binary64 of the lower triangle of `a` (row-major; the upper triangle is not
/// read), sums in increasing k, no fused multiply-add; true when every pivot is
/// > 0. validate(), the fit's rounding to float32 and the file reader and
/// writer all use it: two factorisations that round their sums differently
/// (Eigen's LLT against this one) disagree about a few nearly singular
/// matrices, and the fit once handed out a model that the writer then refused
/// (found by fuzz_fit). When `l` is not null and the test passes, it receives
/// the factor L (row-major, zero above the diagonal; a = L L^T).
bool stored_cholesky(const double* a, double* l = nullptr);

/// The covariance a file holds and validate() tests (spec/format.md 5.1): the
/// symmetric part of `c` (row-major 4 x 4 float32), each entry
/// (c_ij + c_ji) / 2 rounded to float32, widened into `s` (row-major). For a
/// symmetric matrix, every model the library makes, it is the matrix itself.
void stored_symmetric_part(const float* c, double* s);

/// Checks the invariants of a model: M >= 1, array lengths agree with M, all
/// values finite, weights >= 0 summing to 1 within `weight_tolerance`, every
/// covariance symmetric (relative 1e-5) and positive definite (stored_cholesky
/// of its symmetric part rounded to float32, which is what a file holds).
/// Throws Error(InvalidData or Numeric) naming the first violation (component
/// index and what is wrong).
void validate(const Gmm& gmm, double weight_tolerance = 1e-4);

/// Same checks, returning an empty string when valid and the message otherwise.
std::string validation_error(const Gmm& gmm, double weight_tolerance = 1e-4);

}  // namespace sogmm
