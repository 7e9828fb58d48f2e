// Rounding a fitted covariance to float32 storage (see covariance_storage.hpp).
#include "covariance_storage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <cstdlib>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "sogmm/checked.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {
namespace {

using Mat4 = Eigen::Matrix4d;
constexpr double kPlainRoundingNats = 1e-9;
// Corners whose exact divergence is computed (see store_covariance.hpp).
constexpr int kVerified = 8;
// Row and column of the 10 distinct entries of a symmetric 4 x 4 matrix.
constexpr int kRow[10] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 3};
constexpr int kCol[10] = {0, 1, 2, 3, 1, 2, 3, 2, 3, 3};

// Cholesky factor of `c` by validate()'s own test (stored_cholesky), or
// false: a candidate accepted by any other factorisation could be one that
// the writer refuses.
bool factor(const Mat4& c, Mat4& l) {
  using RowMajor4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
  const RowMajor4 a = c;
  RowMajor4 f;
  if (!stored_cholesky(a.data(), f.data())) return false;
  l = f;
  return true;
}

// KL(N(0, S) || N(0, C)) from the Cholesky factors of S and C.
double divergence(const Mat4& ls, const Mat4& lc) {
  const Mat4 w = lc.triangularView<Eigen::Lower>().solve(ls);
  const double log_det_ratio = 2.0 * (lc.diagonal().array().log().sum() - ls.diagonal().array().log().sum());
  return 0.5 * (w.squaredNorm() - 4.0 + log_det_ratio);
}

// The second-order divergence of rounding errors E (symmetric) from the
// target S, with P = S^-1: KL(N(0, S) || N(0, S + E)) = tr(P E P E) / 4 +
// O(E^3). Written in the 10 distinct entries' errors delta (E = sum_a
// delta_a B_a, B_a the symmetric unit matrix of entry a), it is the quadratic
// form delta^T G delta / 4 with G_ab = tr(P B_a P B_b). So the 1024 corners
// can be ranked without a factorisation, at a few operations each along a
// Gray code (one entry flips per step); evaluating tr(P E P E) with two 4 x 4
// products per corner made this ranking most of a fit of tiny clouds.
struct Proxy {
  double g[10][10];
  explicit Proxy(const Mat4& p) {
    for (int a = 0; a < 10; ++a) {
      for (int b = 0; b < 10; ++b) {
        // tr(P (e_i e_j^T) P (e_k e_l^T)) = P_jk P_li, summed over the one or
        // two (row, column) positions of each entry.
        double sum = 0.0;
        for (int ta = 0; ta < (kRow[a] == kCol[a] ? 1 : 2); ++ta) {
          const int i = ta ? kCol[a] : kRow[a], j = ta ? kRow[a] : kCol[a];
          for (int tb = 0; tb < (kRow[b] == kCol[b] ? 1 : 2); ++tb) {
            const int k = tb ? kCol[b] : kRow[b], l = tb ? kRow[b] : kCol[b];
            sum += p(j, k) * p(l, i);
          }
        }
        g[a][b] = sum;
      }
    }
  }
};
// Steps 1-2 of store_covariance for one target; returns the divergence of the
// best positive definite candidate written to `out`, or infinity. At most
// 1 + kVerified factorisations (`factorisations` counts them).
double best_rounding(const Mat4& s, const Mat4& ls, float* out, int& factorisations) {
  float nearest[10], down[10], up[10];
  for (int e = 0; e < 10; ++e) {
    const double v = s(kRow[e], kCol[e]);
    nearest[e] = static_cast<float>(v);
    const double r = nearest[e];
    down[e] = r <= v ? nearest[e] : std::nextafter(nearest[e], -std::numeric_limits<float>::infinity());
    up[e] = r >= v ? nearest[e] : std::nextafter(nearest[e], std::numeric_limits<float>::infinity());
  }
  auto to_matrix = [](const float* entries) {
    Mat4 c;
    for (int e = 0; e < 10; ++e) c(kRow[e], kCol[e]) = c(kCol[e], kRow[e]) = entries[e];
    return c;
  };
  auto write = [&](const float* entries) {
    for (int e = 0; e < 10; ++e) out[4 * kRow[e] + kCol[e]] = out[4 * kCol[e] + kRow[e]] = entries[e];
  };
  Mat4 lc;
  ++factorisations;
  // A positive definite nearest rounding is kept at once when it is close
  // enough, and otherwise stays the candidate to beat: it need not be among
  // the ranked corners verified below.
  double best = std::numeric_limits<double>::infinity();
  if (factor(to_matrix(nearest), lc)) {
    const double d = divergence(ls, lc);
    write(nearest);
    if (d <= kPlainRoundingNats) return d;
    best = d;
  }
  // Rank the 1024 corners (each entry rounded down or up) by the proxy, then
  // factor only the kVerified best: the exact divergence decides among them.
  const Mat4 li = ls.triangularView<Eigen::Lower>().solve(Mat4::Identity());
  const Proxy proxy(li.transpose() * li);
  // Corner 0 (every entry rounded down), then the Gray code: step i flips
  // entry e, the lowest set bit of i; v = G delta follows each flip by one column of G, and
  // q = delta . v is recomputed from the exact delta (the proxy of a nearly
  // singular target is a small difference of large terms: updating q itself
  // drifted by 6e-5 relative over the 1024 steps, this by 8e-6, about what
  // separates two exact evaluation orders).
  double delta[10], v[10], q = 0.0;
  for (int e = 0; e < 10; ++e) delta[e] = static_cast<double>(down[e]) - s(kRow[e], kCol[e]);
  for (int a = 0; a < 10; ++a) {
    v[a] = 0.0;
    for (int b = 0; b < 10; ++b) v[a] += proxy.g[a][b] * delta[b];
    q += delta[a] * v[a];
  }
  std::array<std::pair<double, int>, 1024> ranked;
  ranked[0] = {0.25 * q, 0};
  int mask = 0;
  for (int i = 1; i < 1024; ++i) {
    // The lowest set bit of i (a loop, not __builtin_ctz: GCC emits tzcnt
    // for it, which tools/wheel/check_isa.sh rightly flags outside the kernels).
    int e = 0;
    while (!(i >> e & 1)) ++e;
    mask ^= 1 << e;
    const double t = (mask >> e & 1) ? static_cast<double>(up[e]) - down[e] : static_cast<double>(down[e]) - up[e];
    delta[e] = static_cast<double>((mask >> e & 1) ? up[e] : down[e]) - s(kRow[e], kCol[e]);
    q = 0.0;
    for (int f = 0; f < 10; ++f) {
      v[f] += t * proxy.g[f][e];
      q += delta[f] * v[f];
    }
    ranked[static_cast<std::size_t>(i)] = {0.25 * q, mask};
  }
  // Ties go to the lower mask, so the choice is deterministic.
  std::partial_sort(ranked.begin(), ranked.begin() + kVerified, ranked.end());
  float candidate[10];
  for (int r = 0; r < kVerified; ++r) {
    const int mask = ranked[static_cast<std::size_t>(r)].second;
    for (int e = 0; e < 10; ++e) candidate[e] = (mask >> e & 1) ? up[e] : down[e];
    ++factorisations;
    if (!factor(to_matrix(candidate), lc)) continue;
    const double d = divergence(ls, lc);
    if (d < best) {
      best = d;
      write(candidate);
      if (d <= kPlainRoundingNats) break;
    }
  }
  return best;
}

}  // namespace

double store_covariance(const double* cov, float* out, int* factorisations_out) {
  int factorisations = 0;
  struct Report {
    int& n;
    int* out;
    ~Report() {
      if (out) *out = n;
    }
  } report{factorisations, factorisations_out};
  Mat4 s = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(cov);
  // The symmetric part into a new matrix: assigned to `s` itself, Eigen
  // evaluates it in place, column by column, and reads entries above the
  // diagonal after it overwrote their mirrors (s(0,1) became 0.75 s01 +
  // 0.25 s10). No bit changes for a symmetric input (every caller's today:
  // (a + a) / 2 is exact), only for an asymmetric one.
  s = (0.5 * (s + s.transpose())).eval();
  require(s.allFinite(), ErrorCode::Numeric, "EM: a covariance to store is not finite");
  // float32 storage: an entry beyond its range has no float32 value (and the
  // conversion would be undefined), so such a component cannot be stored.
  require(s.cwiseAbs().maxCoeff() <= static_cast<double>(std::numeric_limits<float>::max()), ErrorCode::Numeric,
          "EM: a covariance entry is beyond the float32 range (" + checked::exact(s.cwiseAbs().maxCoeff()) +
              "); scale the data down");
  Mat4 ls;
  if (factor(s, ls)) {
    const double d = best_rounding(s, ls, out, factorisations);
    if (d < std::numeric_limits<double>::infinity()) return d;
  } else {
    // The EM makes its covariances positive definite by Eigen's LLT; one so
    // nearly singular that stored_cholesky refuses it goes straight to the
    // eigenvalue floor (its factor from LLT serves only the divergence).
    const Eigen::LLT<Mat4> llt(s);
    require(llt.info() == Eigen::Success && Mat4(llt.matrixL()).diagonal().minCoeff() > 0.0, ErrorCode::Numeric,
            "EM: a covariance to store is not positive definite");
    ls = llt.matrixL();
  }
  // Step 3: an eigenvalue floor relative to the component's largest one.
  const Eigen::SelfAdjointEigenSolver<Mat4> eig(s);
  const Eigen::Vector4d lambda = eig.eigenvalues();
  for (double eps = std::ldexp(1.0, -23); eps <= 1.0; eps *= 16.0) {
    const Eigen::Vector4d floored = lambda.cwiseMax(eps * lambda.maxCoeff());
    const Mat4 f = eig.eigenvectors() * floored.asDiagonal() * eig.eigenvectors().transpose();
    Mat4 lf;
    if (!factor(f, lf)) continue;
    if (best_rounding(f, lf, out, factorisations) < std::numeric_limits<double>::infinity()) {
      Mat4 lc;
      Mat4 c = Eigen::Map<const Eigen::Matrix<float, 4, 4, Eigen::RowMajor>>(out).cast<double>();
      ++factorisations;
      factor(c, lc);
      return divergence(ls, lc);
    }
  }
  throw Error(ErrorCode::Numeric, "EM: no positive definite float32 covariance near a fitted one");
}

}  // namespace sogmm::detail
