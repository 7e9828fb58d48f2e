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

// The rotation of section 5.7 read from axes `vecs` (columns, det +1, the
// first the normal): the tilt that takes e0 to the normal, then the turn
// about it; `vecs` comes back with the turn's convention applied (|phi| <=
// 90 degrees: the other two columns may both change sign).
struct Axes {
  double ty, tz, tt;
};
Axes read_axes(Eigen::Matrix3d& vecs) {
  const double n0 = vecs(0, 0), wt = std::sqrt((1 + n0) / 2);
  Axes a{-vecs(2, 0) / (2 * wt), vecs(1, 0) / (2 * wt), 0};
  double tilt[9];
  rotation(a.ty, a.tz, 0, tilt);
  Eigen::Matrix3d m = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(tilt).transpose() * vecs;
  if (m(1, 1) < 0) vecs.col(1) = -vecs.col(1), vecs.col(2) = -vecs.col(2), m.col(1) = -m.col(1);
  a.tt = std::tan(std::atan2(m(2, 1), m(1, 1)) / 2);
  return a;
}

// ---- re-encoding a decoded model ----
//
// A model read from a quantized file and saved again would otherwise be
// quantized afresh: every save could move each component by up to the
// precision again (measured: 0.25 -> 0.334 sigma after two saves at 0.25).
// Its values lie on the grids of the codes they were decoded from, up to the
// float32 rounding of the stored values, so the encoder first looks for those
// codes: per parameter group the coarsest few levels whose grid holds every
// value to within an eighth of a step, tried coarsest first, and codes are
// kept only when they decode to the input's float32 values bit for bit (the
// original's, or codes that decode alike). Where two spatial eigenvalues are
// equal their axes are undetermined, so the rotation codes are searched
// (tilt_candidates, turn_candidates). A component for which none matches (two
// equal eigenvalues whose axes were coded finer than the search: 1-4% of the
// components of real maps at precision 0.5, none on most models) is quantized
// as any other.

// Per parameter group: a finer level than the first that holds the values
// decodes to the same values, so one more guards only against an accidental
// coarse match.
constexpr int kLevelsTried = 2;

// How far float32 rounding of the stored values can have moved a parameter
// read back from them: 16 half-units in the last place of the entries it is
// computed from, amplified as each reading amplifies it (a safety factor of
// about 4 over first-order bounds). A tolerance this tight keeps the search
// from trying codes that cannot match; an eighth of a step caps it.
constexpr double kNoise = 16 * 0x1p-24;

// The coarsest levels b <= max_bits at which every x[i] lies within
// min(noise[i], step / 8) of the grid 2^-b (mantissa: of the mini-float grid
// with b mantissa bits).
std::vector<int> grid_levels(const double* x, const double* noise, int n, int max_bits, bool mantissa) {
  std::vector<int> out;
  for (int b = 0; b <= max_bits && static_cast<int>(out.size()) < kLevelsTried; ++b) {
    bool on = true;
    for (int i = 0; i < n && on; ++i) {
      int k = 0;
      if (mantissa) std::frexp(x[i], &k);
      const double step = mantissa ? std::ldexp(1.0, k - 1 - b) : std::ldexp(1.0, -b);
      const double offset = std::abs(x[i] - step * std::nearbyint(x[i] / step));
      on = offset <= std::min(noise[i], step / 8);
    }
    if (on) out.push_back(b);
  }
  return out;
}

// The decoded parameters of covariance codes `cc` when they decode to `cov`
// bit for bit.
bool covariance_matches(const float* cov, const std::int32_t* cc, Params& p) {
  try {
    p = decode_covariance(cc, 0);
  } catch (const FormatError&) {
    return false;  // codes a reader would refuse
  }
  double s2[16];
  assemble(p, s2);
  for (int i = 0; i < 16; ++i) {
    if (static_cast<float>(s2[i]) != cov[i]) return false;
  }
  return true;
}

// The mean codes on the decoded component `p` if they decode to `mean` bit for bit.
bool mean_matches(const float* mean, const Params& p, std::int32_t* mc) {
  double along[4];  // the mean in decoded standard deviations along the decoded axes
  for (int i = 0; i < 3; ++i) {
    along[i] = ((p.r[i] * mean[0] + p.r[3 + i] * mean[1]) + p.r[6 + i] * mean[2]) / std::sqrt(p.lambda[i]);
  }
  along[3] = mean[3] / std::sqrt(p.v);
  const double reach = std::max({std::abs(mean[0]), std::abs(mean[1]), std::abs(mean[2])});
  const double noise[4] = {kNoise * reach / std::sqrt(p.lambda[0]), kNoise * reach / std::sqrt(p.lambda[1]),
                           kNoise * reach / std::sqrt(p.lambda[2]), kNoise * std::abs(mean[3]) / std::sqrt(p.v)};
  for (const int e : grid_levels(along, noise, 4, kMaxGridBits, false)) {
    mc[0] = e;
    bool fits = true;
    for (int i = 0; i < 4; ++i) {
      const double code = std::nearbyint(std::ldexp(along[i], e));
      fits = fits && fits_int32(code);
      mc[1 + i] = fits ? static_cast<std::int32_t>(code) : 0;
    }
    if (!fits) continue;
    double mu[4];
    assemble_mean(p, mc, mu);
    bool same = true;
    for (int i = 0; i < 4; ++i) same = same && static_cast<float>(mu[i]) == mean[i];
    if (same) return true;
  }
  return false;
}

// Rotation codes to try. Normally those of the tilt and turn read from the
// input's axes, at the coarsest levels whose grids hold them. When two
// spatial eigenvalues are (nearly) equal, float32 rounding leaves their axes
// anywhere in their plane, so the codes are searched on the coarse grids
// (up to kMaxSearchBits) instead, keeping those the axes that are determined
// allow, and the regression and the mean pin the rest down.
constexpr int kMaxSearchBits = 5;
constexpr double kTie = 1e-3;  // relative gap below which two axes are undetermined

struct TiltCode {
  int r;
  std::int64_t y, z;
  double turn;  // the turn angle's tangent of half the angle these axes imply
};

bool tied(double small, double large) { return large - small <= kTie * large; }

// The turn that takes the tilt's image of e2 to the largest axis c2 (either
// sign; |turn| <= 1, the encoder's convention).
double turn_towards(const double tilt[9], const double c2[3]) {
  // T^T c2 = (0, -sin phi, cos phi) up to sign.
  double q1 = 0, q2 = 0;
  for (int a = 0; a < 3; ++a) {
    q1 += tilt[3 * a + 1] * c2[a];
    q2 += tilt[3 * a + 2] * c2[a];
  }
  if (q2 < 0) q1 = -q1, q2 = -q2;
  return std::tan(std::atan2(-q1, q2) / 2);
}

std::vector<TiltCode> tilt_candidates(const std::vector<Axes>& readings, const Params& exact, double spatial,
                                      double axes_noise) {
  std::vector<TiltCode> out;
  const double noise[2] = {axes_noise, axes_noise};
  for (const Axes& a : readings) {
    const double tilt[2] = {a.ty, a.tz};
    for (const int r : grid_levels(tilt, noise, 2, kMaxRotationBits, false)) {
      out.push_back({r, std::llround(std::ldexp(a.ty, r)), std::llround(std::ldexp(a.tz, r)), a.tt});
    }
  }
  if (!tied(exact.lambda[0], exact.lambda[1])) return out;
  // The normal is anywhere in the plane orthogonal to the largest axis c2
  // (known to within its own noise, the rounding over the gap below it).
  const double c2[3] = {exact.r[2], exact.r[5], exact.r[8]};
  const double c2_noise = std::min(kTie, 4 * kNoise * spatial / (exact.lambda[2] - exact.lambda[1]));
  for (int r = 0; r <= kMaxSearchBits; ++r) {
    const std::int64_t one = std::int64_t{1} << r;
    for (std::int64_t y = -one; y <= one; ++y) {
      for (std::int64_t z = -one; z <= one; ++z) {
        if (y * y + z * z > one * one) continue;
        double t[9];
        rotation(std::ldexp(static_cast<double>(y), -r), std::ldexp(static_cast<double>(z), -r), 0, t);
        if (std::abs((t[0] * c2[0] + t[3] * c2[1]) + t[6] * c2[2]) <= c2_noise) out.push_back({r, y, z, turn_towards(t, c2)});
      }
    }
  }
  return out;
}

std::vector<std::pair<int, std::int64_t>> turn_candidates(double tt, const Params& exact, double axes_noise) {
  std::vector<std::pair<int, std::int64_t>> out;
  // Near 90 degrees the decoded axes may read as the turn the other way, -1/tt.
  const double turns[2] = {tt, std::abs(tt) > 0.9 ? -1 / tt : tt};
  for (int k = 0; k < (turns[1] != tt ? 2 : 1); ++k) {
    for (const int u : grid_levels(&turns[k], &axes_noise, 1, kMaxRotationBits, false)) {
      out.emplace_back(u, std::llround(std::ldexp(turns[k], u)));
    }
  }
  if (tied(exact.lambda[1], exact.lambda[2])) {
    for (int u = 0; u <= kMaxSearchBits; ++u) {
      for (std::int64_t t = -(std::int64_t{1} << u); t <= (std::int64_t{1} << u); ++t) out.emplace_back(u, t);
    }
  }
  return out;
}

// The codes of section 5.7 from which `cov` and `mean` were decoded, when
// they can be found (false otherwise). readings: the tilt and turn read from
// the input's eigenvectors as the encoder reads them (and the other way).
bool recover_component(const float* cov, const float* mean, const Params& exact, const std::vector<Axes>& readings,
                       std::int32_t* cc, std::int32_t* mc) {
  const double values[4] = {exact.lambda[0], exact.lambda[1], exact.lambda[2], exact.v};
  const double sxg[3] = {cov[3], cov[7], cov[11]};
  // Noise of what is read from the float32 entries: eigenvalues move by up
  // to the spatial entries' rounding, axes by that over the eigenvalue gap,
  // v with the regression's terms, beta with the gray column's rounding.
  double spatial = 0, gray = 0;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) spatial = std::max(spatial, std::abs(static_cast<double>(cov[4 * a + b])));
    gray = std::max(gray, std::abs(sxg[a]));
  }
  const double gap = std::min(exact.lambda[1] - exact.lambda[0], exact.lambda[2] - exact.lambda[1]);
  const double axes_noise = gap > 0 ? 4 * kNoise * spatial / gap : 1.0;
  // |Sxx^-1 sxg|, bounded through the smallest eigenvalue (sxg^T Sxx^-1 sxg = v |beta|^2).
  const double b2 = (exact.beta[0] * exact.beta[0] + exact.beta[1] * exact.beta[1]) + exact.beta[2] * exact.beta[2];
  const double slope = std::sqrt(exact.v * b2 / exact.lambda[0]);
  const double value_noise[4] = {kNoise * spatial, kNoise * spatial, kNoise * spatial,
                                 kNoise * ((std::abs(static_cast<double>(cov[15])) + 2 * gray * slope) + slope * slope * spatial)};
  // Values on no grid: not a decoded component (a fresh fit's nearly always), and
  // the rotation search below is not needed.
  const std::vector<int> mantissa_levels = grid_levels(values, value_noise, 4, kMaxMantissaBits, true);
  if (mantissa_levels.empty()) return false;
  const std::vector<TiltCode> tilts = tilt_candidates(readings, exact, spatial, axes_noise);
  for (const int f : mantissa_levels) {
    cc[0] = f;
    double lambda[4];
    for (int i = 0; i < 4; ++i) {
      const std::int64_t code = mini_float_code(values[i], f);
      std::int64_t e = 0;
      lambda[i] = mini_float(code, f, &e);
      cc[1 + i] = static_cast<std::int32_t>(code);
    }
    for (const TiltCode& tilt : tilts) {
      if (!fits_int32(static_cast<double>(tilt.y)) || !fits_int32(static_cast<double>(tilt.z))) continue;
      cc[5] = tilt.r;
      cc[7] = static_cast<std::int32_t>(tilt.y);
      cc[8] = static_cast<std::int32_t>(tilt.z);
      for (const auto& [u, t] : turn_candidates(tilt.turn, exact, axes_noise)) {
        cc[6] = u;
        cc[9] = static_cast<std::int32_t>(t);
        // The regression in these axes: sxg = sqrt(v) R Lambda^1/2 beta.
        double rot[9], beta[3];
        rotation(std::ldexp(static_cast<double>(tilt.y), -tilt.r), std::ldexp(static_cast<double>(tilt.z), -tilt.r),
                 std::ldexp(static_cast<double>(t), -u), rot);
        for (int i = 0; i < 3; ++i) {
          beta[i] = ((rot[i] * sxg[0] + rot[3 + i] * sxg[1]) + rot[6 + i] * sxg[2]) / std::sqrt(lambda[i] * lambda[3]);
        }
        double beta_noise[3];
        for (int i = 0; i < 3; ++i) beta_noise[i] = 2 * kNoise * gray / std::sqrt(lambda[i] * lambda[3]);
        for (const int sb : grid_levels(beta, beta_noise, 3, kMaxGridBits, false)) {
          cc[10] = sb;
          for (int i = 0; i < 3; ++i) cc[11 + i] = static_cast<std::int32_t>(std::llround(std::ldexp(beta[i], sb)));
          Params p{};
          if (covariance_matches(cov, cc, p) && mean_matches(mean, p, mc)) return true;
        }
      }
    }
  }
  return false;
}

// The weight codes a decoded model's weights came from: the decoder divides
// the mini-floats omega_k by their sum, so the largest weight times that sum
// is one of the few mini-floats within 1 +- 2^-3 of it; each candidate sum
// is kept when every weight times it lies on the grid and the decoder's
// division gives back every float32 weight.
bool recover_weights(const Gmm& gmm, std::vector<std::int32_t>& codes) {
  const std::size_t m = gmm.size();
  std::size_t top = 0;
  for (std::size_t k = 1; k < m; ++k) top = gmm.weights[k] > gmm.weights[top] ? k : top;
  const double w_top = gmm.weights[top];
  const std::int64_t lo = mini_float_code(w_top * (1 - 1.0 / 8), kWeightMantissaBits);
  const std::int64_t hi = mini_float_code(w_top * (1 + 1.0 / 8), kWeightMantissaBits);
  std::vector<double> omega(m);
  for (std::int64_t c = lo; c <= hi; ++c) {
    std::int64_t e = 0;
    const double scale = mini_float(c, kWeightMantissaBits, &e) / w_top;
    bool on = true;
    double total = 0;
    for (std::size_t k = 0; k < m && on; ++k) {
      const double x = gmm.weights[k] * scale;
      const std::int64_t code = mini_float_code(x, kWeightMantissaBits);
      omega[k] = mini_float(code, kWeightMantissaBits, &e);
      on = e >= kMinExponent && e <= 0 && std::abs(omega[k] / x - 1) <= 1.0 / 1024;
      codes[k] = static_cast<std::int32_t>(code);
      total += omega[k];
    }
    for (std::size_t k = 0; k < m && on; ++k) on = static_cast<float>(omega[k] / total) == gmm.weights[k];
    if (on) return true;
  }
  return false;
}

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
  const Axes axes = read_axes(vecs);
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
  // Tilt codes rounded on a coarse grid can put a decoded normal past n0 = 0
  // (y^2 + z^2 above 1/2), so the axes are also read with the normal the other way.
  Eigen::Matrix3d other = vecs;
  other.col(0) = -other.col(0), other.col(1) = -other.col(1);
  const std::vector<Axes> readings{axes, read_axes(other)};
  if (recover_component(cov, mean, exact, readings, cc, mc)) return true;
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
  double yq = axes.ty, zq = axes.tz;
  for (int r = 0;; ++r) {
    if (r > kMaxRotationBits) return false;
    cc[5] = r;
    std::int64_t y = std::llround(std::ldexp(axes.ty, r)), z = std::llround(std::ldexp(axes.tz, r));
    while (y * y + z * z > (std::int64_t{1} << (2 * r))) (std::llabs(y) > std::llabs(z) ? y : z) -= (std::llabs(y) > std::llabs(z) ? (y > 0 ? 1 : -1) : (z > 0 ? 1 : -1));
    cc[7] = static_cast<std::int32_t>(y);
    cc[8] = static_cast<std::int32_t>(z);
    yq = std::ldexp(static_cast<double>(y), -r);
    zq = std::ldexp(static_cast<double>(z), -r);
    rotation(yq, zq, axes.tt, p.r);
    if (error_of(p, false) <= 0.6 * bound) break;
  }
  for (int u = 0;; ++u) {
    if (u > kMaxRotationBits) return false;
    cc[6] = u;
    const std::int64_t t = std::llround(std::ldexp(axes.tt, u));
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
    if (!(gmm.weights[k] >= std::numeric_limits<float>::min())) return std::nullopt;  // zero or subnormal
  }
  if (!recover_weights(gmm, out.arrays[0])) {
    for (std::size_t k = 0; k < m; ++k) {
      out.arrays[0][k] = static_cast<std::int32_t>(mini_float_code(gmm.weights[k], kWeightMantissaBits));
    }
  }
  for (std::size_t k = 0; k < m; ++k) {
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
