// Quantized components: the decoding formulas of spec/format.md section 5.7
// (binary64, no fused multiply-add: the format library is built with
// -ffp-contract=off, so every reader rounds alike) and the encoder that picks,
// per component, the coarsest grids whose decoding still meets the bound.
#include "quantized_components.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "container.hpp"

namespace sogmm::format::detail {
namespace {

using Mat4 = Eigen::Matrix4d;

// Ranges of the codes (section 5.7): exponents of the mini-floats, grids.
constexpr int kMaxMantissaBits = 16;   // f
constexpr int kMinExponent = -126;     // floor(c / 2^f)
constexpr int kMaxExponent = 127;
constexpr int kWeightMantissaBits = 3;
constexpr int kMaxRotationBits = 24;   // r: q^2 < 2^48, so the sums below are exact
constexpr int kMaxGridBits = 40;       // s (regression) and e (mean)

[[noreturn]] void bad_code(std::uint64_t k, const std::string& what) {
  fail(ErrorCode::InvalidData, "bad_quantization", "component " + std::to_string(k) + ": " + what);
}

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

// (2^f + (c mod 2^f)) 2^(floor(c / 2^f) - f): a float with f mantissa bits,
// relative step 2^-f. Exact in binary64. Exponent range checked by the caller.
double mini_float(std::int64_t c, int f, std::int64_t* exponent) {
  const std::int64_t big = std::int64_t{1} << f;
  const std::int64_t e = floor_div(c, big);
  *exponent = e;
  return std::ldexp(static_cast<double>(big + (c - e * big)), static_cast<int>(e) - f);
}

// The code of the nearest mini-float to x > 0 (ties away from zero).
std::int64_t mini_float_code(double x, int f) {
  int k = 0;
  const double m = std::frexp(x, &k);  // x = m 2^k, m in [0.5, 1)
  std::int64_t e = k - 1;
  const std::int64_t big = std::int64_t{1} << f;
  std::int64_t mantissa = std::llround((2 * m - 1) * static_cast<double>(big));
  if (mantissa == big) {
    mantissa = 0;
    ++e;
  }
  return e * big + mantissa;
}

// A component's parameters: spatial eigenvalues and rotation (columns the
// eigenvectors, row-major), the regression of gray on x, y, z in whitened
// units, and the conditional variance of gray.
struct Params {
  double lambda[3];
  double r[9];
  double beta[3];
  double v;
};

// The rotation whose first column is the normal (the smallest eigenvalue's
// axis), as two quaternions (section 5.7): a tilt (w, 0, y, z), w =
// sqrt(1 - y^2 - z^2), that takes e0 to the normal, then a turn (1, t, 0, 0)
// about e0; R is the matrix of their product, normalised. Only + - * / and
// sqrt, so every reader computes the same bits.
void rotation(double y, double z, double t, double r[9]) {
  const double w = std::sqrt(1 - (y * y + z * z));
  const double a[4] = {w, w * t, y + z * t, z - y * t};
  const double n = ((a[0] * a[0] + a[1] * a[1]) + a[2] * a[2]) + a[3] * a[3];
  const double s = 2 / n;
  r[0] = 1 - s * (a[2] * a[2] + a[3] * a[3]);
  r[1] = s * (a[1] * a[2] - a[0] * a[3]);
  r[2] = s * (a[1] * a[3] + a[0] * a[2]);
  r[3] = s * (a[1] * a[2] + a[0] * a[3]);
  r[4] = 1 - s * (a[1] * a[1] + a[3] * a[3]);
  r[5] = s * (a[2] * a[3] - a[0] * a[1]);
  r[6] = s * (a[1] * a[3] - a[0] * a[2]);
  r[7] = s * (a[2] * a[3] + a[0] * a[1]);
  r[8] = 1 - s * (a[1] * a[1] + a[2] * a[2]);
}

// The covariance of the parameters, in binary64 (section 5.7): T T^T with
// T = [[R Lambda^1/2, 0], [sqrt(v) beta^T, sqrt(v)]].
void assemble(const Params& p, double s[16]) {
  for (int a = 0; a < 3; ++a) {
    for (int b = a; b < 3; ++b) {
      s[4 * a + b] = s[4 * b + a] = ((p.lambda[0] * p.r[3 * a]) * p.r[3 * b] +
                                     (p.lambda[1] * p.r[3 * a + 1]) * p.r[3 * b + 1]) +
                                    (p.lambda[2] * p.r[3 * a + 2]) * p.r[3 * b + 2];
    }
  }
  double t[3];
  for (int i = 0; i < 3; ++i) t[i] = std::sqrt(p.lambda[i]) * p.beta[i];
  const double sv = std::sqrt(p.v);
  for (int a = 0; a < 3; ++a) {
    s[4 * a + 3] = s[12 + a] = sv * ((p.r[3 * a] * t[0] + p.r[3 * a + 1] * t[1]) + p.r[3 * a + 2] * t[2]);
  }
  s[15] = p.v * (1 + ((p.beta[0] * p.beta[0] + p.beta[1] * p.beta[1]) + p.beta[2] * p.beta[2]));
}

// The mean of the mean codes e, U (3), G given the decoded parameters.
void assemble_mean(const Params& p, const std::int32_t* c, double mu[4]) {
  const double h = std::ldexp(1.0, -c[0]);
  double y[3];
  for (int i = 0; i < 3; ++i) y[i] = std::sqrt(p.lambda[i]) * (c[1 + i] * h);
  for (int a = 0; a < 3; ++a) mu[a] = (p.r[3 * a] * y[0] + p.r[3 * a + 1] * y[1]) + p.r[3 * a + 2] * y[2];
  mu[3] = std::sqrt(p.v) * (c[4] * h);
}

// Section 5.7's checks and formulas for one component's covariance codes.
Params decode_covariance(const std::int32_t* c, std::uint64_t k) {
  Params p{};
  const int f = c[0];
  if (f < 0 || f > kMaxMantissaBits) bad_code(k, "mantissa bits f = " + std::to_string(f) + " not in [0, 16]");
  for (int i = 0; i < 4; ++i) {
    std::int64_t e = 0;
    const double value = mini_float(c[1 + i], f, &e);
    if (e < kMinExponent || e > kMaxExponent) bad_code(k, "variance code " + std::to_string(c[1 + i]) + " out of range");
    (i < 3 ? p.lambda[i] : p.v) = value;
  }
  const int r = c[5], u = c[6];
  if (r < 0 || r > kMaxRotationBits) bad_code(k, "tilt bits r = " + std::to_string(r) + " not in [0, 24]");
  if (u < 0 || u > kMaxRotationBits) bad_code(k, "turn bits u = " + std::to_string(u) + " not in [0, 24]");
  const std::int64_t ty = c[7], tz = c[8], tt = c[9];
  // Each square is at most 2^62, their sum at most 2^63: exact in 64 unsigned bits.
  if (static_cast<std::uint64_t>(ty * ty) + static_cast<std::uint64_t>(tz * tz) > (std::uint64_t{1} << (2 * r))) {
    bad_code(k, "tilt codes of norm above 1");
  }
  if (tt > (std::int64_t{1} << u) || tt < -(std::int64_t{1} << u)) bad_code(k, "turn code beyond 2^u");
  rotation(std::ldexp(static_cast<double>(ty), -r), std::ldexp(static_cast<double>(tz), -r),
           std::ldexp(static_cast<double>(tt), -u), p.r);
  const int s = c[10];
  if (s < 0 || s > kMaxGridBits) bad_code(k, "regression bits s = " + std::to_string(s) + " not in [0, 40]");
  for (int i = 0; i < 3; ++i) p.beta[i] = std::ldexp(static_cast<double>(c[11 + i]), -s);
  return p;
}

// ---- encoder ----

// max |eigenvalue - 1| of L^-1 S' L^-T: the covariance's error in its own metric.
double covariance_error(const Eigen::LLT<Mat4>& llt, const double s2[16]) {
  const Mat4 b = Eigen::Map<const Mat4>(s2);
  const Mat4 l = llt.matrixL();
  const Mat4 x = l.triangularView<Eigen::Lower>().solve(b);
  const Mat4 w = l.triangularView<Eigen::Lower>().solve(x.transpose());
  const Eigen::Vector4d ev = Eigen::SelfAdjointEigenSolver<Mat4>(0.5 * (w + w.transpose()), Eigen::EigenvaluesOnly)
                                 .eigenvalues();
  return std::max(std::abs(ev(0) - 1), std::abs(ev(3) - 1));
}

// S' as float32 values, widened back: what a reader returns.
void round_to_float(double s[16]) {
  for (int i = 0; i < 16; ++i) s[i] = static_cast<float>(s[i]);
}

bool fits_int32(double v) { return std::abs(v) < 2147483647.0; }

// Codes of one component (covariance and mean); false when none meets the bound.
bool quantize_component(const float* cov, const float* mean, double precision, std::int32_t* cc, std::int32_t* mc) {
  Mat4 s;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) s(i, j) = 0.5 * (static_cast<double>(cov[4 * i + j]) + cov[4 * j + i]);
  }
  const Eigen::LLT<Mat4> llt(s);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Matrix3d sxx = s.topLeftCorner<3, 3>();
  const Eigen::Vector3d sxg = s.block<3, 1>(0, 3);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(sxx);
  if (es.info() != Eigen::Success || es.eigenvalues()(0) <= 0) return false;
  Eigen::Matrix3d vecs = es.eigenvectors();
  if (vecs.determinant() < 0) vecs.col(2) = -vecs.col(2);
  // The rotation as a tilt that takes e0 to the normal (n0 >= 0: the
  // eigenvector's sign is free) and a turn about it (|phi| <= 90 degrees:
  // the other two columns may both change sign).
  if (vecs(0, 0) < 0) vecs.col(0) = -vecs.col(0), vecs.col(1) = -vecs.col(1);
  const double n0 = vecs(0, 0), wt = std::sqrt((1 + n0) / 2);
  const double ty = -vecs(2, 0) / (2 * wt), tz = vecs(1, 0) / (2 * wt);
  double tilt[9];
  rotation(ty, tz, 0, tilt);
  Eigen::Matrix3d m = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(tilt).transpose() * vecs;
  if (m(1, 1) < 0) vecs.col(1) = -vecs.col(1), vecs.col(2) = -vecs.col(2), m.col(1) = -m.col(1);
  const double tt = std::tan(std::atan2(m(2, 1), m(1, 1)) / 2);
  const Eigen::Vector3d b = sxx.ldlt().solve(sxg);  // regression of gray on x, y, z
  const double v = s(3, 3) - sxg.dot(b);
  if (!(v > 0)) return false;
  Params exact{};
  for (int i = 0; i < 3; ++i) {
    exact.lambda[i] = es.eigenvalues()(i);
    exact.beta[i] = vecs.col(i).dot(sxg) / std::sqrt(exact.lambda[i] * v);
    for (int a = 0; a < 3; ++a) exact.r[3 * a + i] = vecs(a, i);
  }
  exact.v = v;
  const double bound = precision * (1 - 1e-6);  // a margin for other eigen solvers
  double s2[16];
  auto error_of = [&](const Params& p, bool as_float) {
    assemble(p, s2);
    if (as_float) round_to_float(s2);
    return covariance_error(llt, s2);
  };

  // 1. Eigenvalues and conditional variance: f mantissa bits.
  Params p = exact;
  int f = 0;
  for (;; ++f) {
    if (f > kMaxMantissaBits) return false;
    cc[0] = f;
    for (int i = 0; i < 4; ++i) {
      const std::int64_t code = mini_float_code(i < 3 ? exact.lambda[i] : exact.v, f);
      if (!fits_int32(static_cast<double>(code))) return false;
      cc[1 + i] = static_cast<std::int32_t>(code);
      std::int64_t e = 0;
      (i < 3 ? p.lambda[i] : p.v) = mini_float(code, f, &e);
      if (e < kMinExponent || e > kMaxExponent) return false;
    }
    if (error_of(p, false) <= 0.35 * bound) break;
  }
  // 2. Rotation: the tilt on r bits, then the turn on u bits.
  double yq = ty, zq = tz;
  for (int r = 0;; ++r) {
    if (r > kMaxRotationBits) return false;
    cc[5] = r;
    std::int64_t y = std::llround(std::ldexp(ty, r)), z = std::llround(std::ldexp(tz, r));
    while (y * y + z * z > (std::int64_t{1} << (2 * r))) (std::llabs(y) > std::llabs(z) ? y : z) -= (std::llabs(y) > std::llabs(z) ? (y > 0 ? 1 : -1) : (z > 0 ? 1 : -1));
    cc[7] = static_cast<std::int32_t>(y);
    cc[8] = static_cast<std::int32_t>(z);
    yq = std::ldexp(static_cast<double>(y), -r);
    zq = std::ldexp(static_cast<double>(z), -r);
    rotation(yq, zq, tt, p.r);
    if (error_of(p, false) <= 0.6 * bound) break;
  }
  for (int u = 0;; ++u) {
    if (u > kMaxRotationBits) return false;
    cc[6] = u;
    const std::int64_t t = std::llround(std::ldexp(tt, u));
    cc[9] = static_cast<std::int32_t>(t);
    rotation(yq, zq, std::ldexp(static_cast<double>(t), -u), p.r);
    if (error_of(p, false) <= 0.75 * bound) break;
  }
  // 3. Regression of gray: s bits; the whole covariance, as float32, meets the bound.
  for (int sb = 0;; ++sb) {
    if (sb > kMaxGridBits) return false;
    cc[10] = sb;
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
      const double code = std::nearbyint(std::ldexp(exact.beta[i], sb));
      ok = ok && fits_int32(code);
      cc[11 + i] = ok ? static_cast<std::int32_t>(code) : 0;
      p.beta[i] = std::ldexp(code, -sb);
    }
    if (!ok) return false;
    if (error_of(p, true) <= bound && stored_cholesky(s2)) break;
  }
  // 4. Mean: e bits on the grid of the decoded standard deviations, gray
  // chosen to cancel what the spatial rounding moved along the regression.
  const Eigen::Vector3d mx(mean[0], mean[1], mean[2]);
  const Eigen::Vector4d m0(mean[0], mean[1], mean[2], mean[3]);
  for (int e = 0;; ++e) {
    if (e > kMaxGridBits) return false;
    mc[0] = e;
    for (int i = 0; i < 3; ++i) {
      const double along = (p.r[i] * mx(0) + p.r[3 + i] * mx(1)) + p.r[6 + i] * mx(2);
      const double code = std::nearbyint(std::ldexp(along / std::sqrt(p.lambda[i]), e));
      if (!fits_int32(code)) return false;
      mc[1 + i] = static_cast<std::int32_t>(code);
    }
    mc[4] = 0;
    double mu[4];
    assemble_mean(p, mc, mu);
    const double moved = b.dot(Eigen::Vector3d(static_cast<float>(mu[0]), static_cast<float>(mu[1]),
                                               static_cast<float>(mu[2])) - mx);
    const double g = std::nearbyint(std::ldexp((mean[3] + moved) / std::sqrt(p.v), e));
    if (!fits_int32(g)) return false;
    mc[4] = static_cast<std::int32_t>(g);
    assemble_mean(p, mc, mu);
    Eigen::Vector4d d;
    for (int i = 0; i < 4; ++i) d(i) = static_cast<double>(static_cast<float>(mu[i])) - m0(i);
    if (llt.matrixL().solve(d).norm() <= bound) break;
  }
  return true;
}

}  // namespace

std::optional<ComponentCodes> quantize(const Gmm& gmm, double precision) {
  const std::size_t m = gmm.size();
  ComponentCodes out;
  for (int i = 0; i < 3; ++i) out.arrays[i].resize(m * kCodeColumns[i]);
  for (std::size_t k = 0; k < m; ++k) {
    const double w = gmm.weights[k];
    if (!(w >= std::numeric_limits<float>::min())) return std::nullopt;  // zero or subnormal
    out.arrays[0][k] = static_cast<std::int32_t>(mini_float_code(w, kWeightMantissaBits));
    if (!quantize_component(gmm.covariance(k), gmm.mean(k), precision, &out.arrays[2][14 * k],
                            &out.arrays[1][5 * k])) {
      return std::nullopt;
    }
  }
  return out;
}

void dequantize(const ComponentCodes& codes, std::uint64_t m, Gmm& out) {
  out.resize(static_cast<std::size_t>(m));
  double total = 0;
  std::vector<double> omega(static_cast<std::size_t>(m));
  for (std::uint64_t k = 0; k < m; ++k) {
    std::int64_t e = 0;
    omega[k] = mini_float(codes.arrays[0][k], kWeightMantissaBits, &e);
    if (e < kMinExponent || e > 0) bad_code(k, "weight code " + std::to_string(codes.arrays[0][k]) + " out of range");
    total += omega[k];
  }
  for (std::uint64_t k = 0; k < m; ++k) {
    out.weights[k] = static_cast<float>(omega[k] / total);
    const Params p = decode_covariance(&codes.arrays[2][14 * k], k);
    const std::int32_t* mc = &codes.arrays[1][5 * k];
    if (mc[0] < 0 || mc[0] > kMaxGridBits) bad_code(k, "mean bits e = " + std::to_string(mc[0]) + " not in [0, 40]");
    double s[16], mu[4];
    assemble(p, s);
    assemble_mean(p, mc, mu);
    float* c = out.covariances.data() + 16 * k;
    for (int i = 0; i < 16; ++i) c[i] = static_cast<float>(s[i]);
    for (int i = 0; i < 4; ++i) out.means[4 * k + i] = static_cast<float>(mu[i]);
  }
}

}  // namespace sogmm::format::detail
