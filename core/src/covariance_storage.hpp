// Rounding a fitted covariance to float32 storage without losing positive
// definiteness (private to the EM).
#pragma once

namespace sogmm::detail {

/// Writes the float32 covariance (row-major 4 x 4) that represents the
/// symmetric positive definite double covariance `cov` best, and is positive
/// definite itself by the library's one test, stored_cholesky (sogmm/gmm.hpp),
/// which validate() and the file writer make too.
///
/// Why: float32 keeps ~7 digits, so a thin component far larger than it is
/// thick (a 1 km plane with 1 cm noise: eigenvalues 1e4 and 1e-4 m^2) loses
/// its small eigenvalue to the rounding of the large entries, and plain
/// rounding can even give an indefinite matrix. The rule:
/// 1. round to nearest; keep it if it is positive definite and its
///    Kullback-Leibler divergence KL(N(0, cov) || N(0, stored)) is below
///    1e-9 nats (every component of an ordinary scene);
/// 2. otherwise rank every combination of rounding each of the 10 distinct
///    entries down or up (1024 candidates) by the second-order divergence
///    tr(P E P E) / 4 of its rounding errors E (P = cov^-1; no factorisation),
///    and keep, of the 8 best by that measure and the nearest rounding of
///    step 1 (when positive definite), the positive definite one with the
///    smallest exact divergence: the rounding errors then cancel along the
///    thin direction instead of swamping it, and the result is never worse
///    than plain rounding;
/// 3. if none is positive definite, raise the eigenvalues of `cov` to at least
///    eps x its largest eigenvalue (eps = 2^-23, 2^-19, ..., 2^-3: a floor
///    relative to the component's own scale; x16 per attempt) and repeat 1-2.
/// The cost is bounded whatever the input: at most 9 factorisations per
/// attempt, 6 attempts after the first and one to score the
/// floored result: 64 in all (an exhaustive search of
/// the corners once took 1024-3584 per near-singular component, which made
/// fits of tiny clouds with tiny floors slow; issue 14). `factorisations`
/// (optional) receives how many were made.
/// `cov` must be finite, symmetric and positive definite (by Eigen's LLT at
/// least, the EM's own test: a target stored_cholesky refuses starts at step
/// 3; the map's fused components are stored here too). Returns the
/// divergence of the stored matrix from `cov` (nats).
double store_covariance(const double* cov, float* out, int* factorisations = nullptr);

}  // namespace sogmm::detail
