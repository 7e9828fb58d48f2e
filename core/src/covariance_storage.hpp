// Rounding a fitted covariance to float32 storage without losing positive
// definiteness (private to the EM).
#pragma once

namespace sogmm::detail {

/// Writes the float32 covariance (row-major 4 x 4) that represents the
/// symmetric positive definite double covariance `cov` best, and is positive
/// definite itself (the test of validate(): a Cholesky factorisation in
/// double of the stored values succeeds with a positive diagonal).
///
/// Why: float32 keeps ~7 digits, so a thin component far larger than it is
/// thick (a 1 km plane with 1 cm noise: eigenvalues 1e4 and 1e-4 m^2) loses
/// its small eigenvalue to the rounding of the large entries, and plain
/// rounding can even give an indefinite matrix. The rule:
/// 1. round to nearest; keep it if it is positive definite and its
///    Kullback-Leibler divergence KL(N(0, cov) || N(0, stored)) is below
///    1e-9 nats (every component of an ordinary scene);
/// 2. otherwise try every combination of rounding each of the 10 distinct
///    entries down or up (1024 candidates), and keep the positive definite one
///    with the smallest divergence, then move single entries by up to 8 float
///    steps while that lowers it: the rounding errors then cancel along the
///    thin direction instead of swamping it;
/// 3. if none is positive definite, raise the eigenvalues of `cov` to at least
///    eps x its largest eigenvalue (eps from 2^-23, x4 per attempt: a floor
///    relative to the component's own scale) and repeat 1-2.
/// `cov` must be finite, symmetric and positive definite. Returns the
/// divergence of the stored matrix from `cov` (nats).
double store_covariance(const double* cov, float* out);

}  // namespace sogmm::detail
