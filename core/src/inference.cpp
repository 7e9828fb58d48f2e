// Scoring, sampling, gray regression, merging and rigid transforms of a model.
#include "sogmm/inference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include "parallel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/random.hpp"
#include "sogmm/model.hpp"

namespace sogmm {
namespace {

constexpr double kLog2Pi = 1.8378770664093454836;
using Mat4 = Eigen::Matrix4d;
using Mat3 = Eigen::Matrix3d;

Mat4 covariance_of(const Gmm& gmm, std::size_t k) {
  return Eigen::Map<const Eigen::Matrix<float, 4, 4, Eigen::RowMajor>>(gmm.covariance(k)).cast<double>();
}
Eigen::Vector4d mean_of(const Gmm& gmm, std::size_t k) {
  return Eigen::Map<const Eigen::Vector4f>(gmm.mean(k)).cast<double>();
}

// The Cholesky factorisation of a covariance (or a block of one), checked:
// validate() accepts the float32 model, yet a sub-block or a derived matrix
// could still fail in double, and an unchecked failure would turn into NaN
// answers silently.
template <class M>
Eigen::LLT<M> checked_llt(const M& c, const char* what, std::size_t k = static_cast<std::size_t>(-1)) {
  Eigen::LLT<M> llt(c);
  if (llt.info() != Eigen::Success)
    throw Error(ErrorCode::Numeric, std::string(what) +
                                        (k == static_cast<std::size_t>(-1) ? "" : " of component " + std::to_string(k)) +
                                        " is not positive definite");
  return llt;
}

// Per-component quantities for Gaussian densities in D dimensions (D = 3 or
// 4): the inverse Cholesky factor and log(weight) - log det(L) - D/2 log 2 pi.
template <int D>
struct DensityCache {
  std::vector<Eigen::Matrix<double, D, 1>> mean;
  std::vector<Eigen::Matrix<double, D, D>> inv_l;
  std::vector<double> log_const;

  explicit DensityCache(const Gmm& gmm) {
    validate(gmm);
    const std::size_t m = gmm.size();
    mean.resize(m);
    inv_l.resize(m);
    log_const.resize(m);
    for (std::size_t k = 0; k < m; ++k) {
      const Eigen::Matrix<double, D, D> c = covariance_of(gmm, k).template topLeftCorner<D, D>();
      const Eigen::Matrix<double, D, D> l = checked_llt(c, "covariance", k).matrixL();
      inv_l[k] = l.template triangularView<Eigen::Lower>().solve(Eigen::Matrix<double, D, D>::Identity());
      mean[k] = mean_of(gmm, k).template head<D>();
      const double w = gmm.weights[k];
      log_const[k] = (w > 0 ? std::log(w) : -std::numeric_limits<double>::infinity()) -
                     l.diagonal().array().log().sum() - 0.5 * D * kLog2Pi;
    }
  }
  // log(w_k N(x | mu_k, Sigma_k)).
  double log_component(std::size_t k, const Eigen::Matrix<double, D, 1>& x) const {
    return log_const[k] - 0.5 * (inv_l[k] * (x - mean[k])).squaredNorm();
  }
};

// exp(x) is exactly 0 in double for x below about -745.13; terms further
// than this below the largest are skipped without changing any sum.
constexpr double kExpUnderflow = -746.0;

double log_sum_exp(const double* v, std::size_t n) {
  const double mx = *std::max_element(v, v + n);
  if (!std::isfinite(mx)) return mx;
  double s = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = v[i] - mx;
    if (d >= kExpUnderflow) s += std::exp(d);
  }
  return mx + std::log(s);
}

// Rows of `width` floats; the message (built only on failure) names the row.
void require_finite(const float* v, std::size_t rows, int width, const char* what) {
  const std::size_t count = checked::mul<std::size_t>(rows, static_cast<std::size_t>(width), "input size");
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(v[i]))
      throw Error(ErrorCode::InvalidData, std::string(what) + " has a non-finite value (NaN or Inf) at row " +
                                              std::to_string(i / static_cast<std::size_t>(width)));
}

// Points handed to a thread at a time: each costs O(M), so scheduling is cheap.
constexpr std::size_t kPointsPerChunk = 64;

// `m` doubles per thread of OpenMP's default team, allocated before the
// parallel loop so that running out of memory is an ordinary exception. Rows
// are 64 bytes apart, so no two threads write to one cache line.
struct PerThreadScratch {
  explicit PerThreadScratch(std::size_t m)
      : threads(detail::team_size(0)),
        stride(checked::add<std::size_t>(m, 8, "scratch row")),
        values(checked::mul<std::size_t>(static_cast<std::size_t>(threads), stride, "scratch size")) {}
  double* of(int thread) { return values.data() + static_cast<std::size_t>(thread) * stride; }
  int threads;
  std::size_t stride;
  std::vector<double> values;
};

template <int D>
void score_dims(const Gmm& gmm, const float* points, std::size_t n, double* out) {
  const DensityCache<D> cache(gmm);
  const std::size_t m = gmm.size();
  PerThreadScratch scratch(m);
  detail::parallel_for(n, scratch.threads, kPointsPerChunk, [&](std::size_t i, int thread) {
    double* lp = scratch.of(thread);
    const Eigen::Matrix<double, D, 1> x = Eigen::Map<const Eigen::Matrix<float, D, 1>>(points + D * i).template cast<double>();
    for (std::size_t k = 0; k < m; ++k) lp[k] = cache.log_component(k, x);
    out[i] = log_sum_exp(lp, m);
  });
}

}  // namespace

void score_samples(const Gmm& gmm, const float* points, std::size_t n, int dims, double* out) {
  require(dims == 3 || dims == 4, ErrorCode::InvalidArgument, "dims must be 3 or 4, got " + std::to_string(dims));
  if (n == 0) return;
  require(points != nullptr && out != nullptr, ErrorCode::InvalidArgument, "points and output must not be null");
  require_finite(points, n, dims, "points to score");
  if (dims == 4)
    score_dims<4>(gmm, points, n, out);
  else
    score_dims<3>(gmm, points, n, out);
}

double mean_log_likelihood(const Gmm& gmm, const float* points, std::size_t n, int dims) {
  require(n > 0, ErrorCode::InvalidData, "no points to score");
  std::vector<double> lp(n);
  score_samples(gmm, points, n, dims, lp.data());
  double s = 0.0;
  for (double v : lp) s += v;
  return s / static_cast<double>(n);
}

void sample(const Gmm& gmm, std::size_t n, std::uint64_t seed, int dims, float* out, double truncation) {
  require(dims == 3 || dims == 4, ErrorCode::InvalidArgument, "dims must be 3 or 4, got " + std::to_string(dims));
  require(truncation > 0, ErrorCode::InvalidArgument, "truncation must be > 0");
  validate(gmm);
  if (n == 0) return;
  require(out != nullptr, ErrorCode::InvalidArgument, "output must not be null");
  const std::size_t m = gmm.size();
  Rng rng(seed);
  // Multinomial counts: each draw picks a component by its cumulative weight.
  std::vector<double> cumulative(m);
  double running = 0.0;
  for (std::size_t k = 0; k < m; ++k) cumulative[k] = (running += gmm.weights[k]);
  std::vector<std::size_t> counts(m, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = rng.uniform() * running;
    const std::size_t k = std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin();
    ++counts[std::min(k, m - 1)];
  }
  const TruncatedNormal truncated(truncation);
  detail::progress_begin(Stage::Sampling, n);
  std::size_t row = 0;
  for (std::size_t k = 0; k < m; ++k) {
    if (counts[k] == 0) continue;
    const Mat4 l = checked_llt(covariance_of(gmm, k), "covariance", k).matrixL();
    const Eigen::Vector4d mu = mean_of(gmm, k);
    for (std::size_t j = 0; j < counts[k]; ++j, ++row) {
      if (row % kPointsPerChunk == 0) detail::progress_at(row);
      Eigen::Vector4d z;
      for (int i = 0; i < 4; ++i) z[i] = std::isinf(truncation) ? rng.normal() : truncated(rng);
      const Eigen::Vector4d x = mu + l * z;
      for (int i = 0; i < dims; ++i) out[dims * row + i] = static_cast<float>(x[i]);
    }
  }
}

namespace {

// The prior of the gray regression (issue 14 item 4): one broad Gaussian
// component in xyz that carries the mixture's prior gray (mean sum pi_m mu_g
// and total variance sum pi_m (Sigma_gg + (mu_g - mean)^2)) and no spatial
// gain. Its covariance is kBackgroundScale^2 times the mixture's total
// spatial covariance and its weight kBackgroundWeight times the mixture's, so
// on the surface its share is negligible (~1e-9 of a component at 1 sigma),
// while a point beyond about 6.5 standard deviations of every component is
// explained by it: the answer falls back smoothly to the prior instead of
// following the nearest component's regression line without bound. Both
// constants are dimensionless, so translating or scaling the model moves the
// background with it.
constexpr double kBackgroundWeight = 1e-6;
constexpr double kBackgroundScale = 10.0;

struct GrayBackground {
  Eigen::Vector3d mean;
  Mat3 inv_l;
  double log_const = 0.0;
  double gray = 0.0;
  double variance = 0.0;

  explicit GrayBackground(const Gmm& gmm) {
    // Weighted moments in double, centred (two passes), so that a model far
    // from the origin or with large gray means loses nothing to cancellation.
    const std::size_t m = gmm.size();
    double w = 0.0;
    Eigen::Vector4d mu = Eigen::Vector4d::Zero();
    for (std::size_t k = 0; k < m; ++k) {
      w += gmm.weights[k];
      mu += gmm.weights[k] * mean_of(gmm, k);
    }
    mu /= w;
    Mat4 c = Mat4::Zero();
    for (std::size_t k = 0; k < m; ++k) {
      const Eigen::Vector4d d = mean_of(gmm, k) - mu;
      c += gmm.weights[k] * (covariance_of(gmm, k) + d * d.transpose());
    }
    c /= w;
    mean = mu.head<3>();
    gray = mu[3];
    variance = c(3, 3);
    const Mat3 cov = kBackgroundScale * kBackgroundScale * c.topLeftCorner<3, 3>();
    const Mat3 l = checked_llt(cov, "the prior's spatial covariance").matrixL();
    inv_l = l.triangularView<Eigen::Lower>().solve(Mat3::Identity());
    log_const = std::log(kBackgroundWeight * w) - l.diagonal().array().log().sum() - 1.5 * kLog2Pi;
  }
  double log_density(const Eigen::Vector3d& x) const { return log_const - 0.5 * (inv_l * (x - mean)).squaredNorm(); }
};

}  // namespace

void regress_gray(const Gmm& gmm, const float* xyz, std::size_t n, float* mean_out, float* variance_out) {
  if (n == 0) return;
  require(xyz != nullptr && mean_out != nullptr, ErrorCode::InvalidArgument, "points and output must not be null");
  require_finite(xyz, n, 3, "points to regress");
  const DensityCache<3> cache(gmm);
  const GrayBackground background(gmm);
  const std::size_t m = gmm.size();
  // Per component: gain A = Sigma_gx Sigma_xx^-1 and conditional variance;
  // entry m is the background (no gain, the prior's gray and variance).
  std::vector<Eigen::RowVector3d> gain(m + 1, Eigen::RowVector3d::Zero());
  std::vector<double> cond_var(m + 1), mean_g(m + 1);
  for (std::size_t k = 0; k < m; ++k) {
    const Mat4 c = covariance_of(gmm, k);
    const Mat3 sxx = c.topLeftCorner<3, 3>();
    const Eigen::Vector3d sxg = c.topRightCorner<3, 1>();
    gain[k] = checked_llt(sxx, "spatial covariance", k).solve(sxg).transpose();
    cond_var[k] = std::max(0.0, c(3, 3) - gain[k].dot(sxg));
    mean_g[k] = gmm.mean(k)[3];
  }
  cond_var[m] = background.variance;
  mean_g[m] = background.gray;
  // Two rows per thread: log-weights, then the per-component conditional means.
  const std::size_t row = checked::add<std::size_t>(m, 1, "components");
  PerThreadScratch scratch(checked::mul<std::size_t>(row, 2, "scratch row"));
  detail::parallel_for(n, scratch.threads, kPointsPerChunk, [&](std::size_t i, int thread) {
    double* lw = scratch.of(thread);
    double* lambda = lw + row;
    const Eigen::Vector3d x = Eigen::Map<const Eigen::Vector3f>(xyz + 3 * i).cast<double>();
    for (std::size_t k = 0; k < m; ++k) lw[k] = cache.log_component(k, x);
    lw[m] = background.log_density(x);
    const double mx = *std::max_element(lw, lw + row);
    // One exp per entry that does not underflow: unnormalised weights
    // e_k = exp(lw_k - max), normalised by their sum.
    double sum = 0.0, mu = 0.0;
    for (std::size_t k = 0; k < row; ++k) {
      const double d = lw[k] - mx;
      lw[k] = d >= kExpUnderflow ? std::exp(d) : 0.0;
      if (lw[k] == 0.0) continue;
      lambda[k] = k < m ? mean_g[k] + gain[k].dot(x - cache.mean[k]) : mean_g[k];
      sum += lw[k];
      mu += lw[k] * lambda[k];
    }
    mu /= sum;
    mean_out[i] = static_cast<float>(mu);
    if (!variance_out) return;
    // Law of total variance about the mean just found (a sum of non-negative
    // terms, not a difference of second moments, which cancels far out).
    double var = 0.0;
    for (std::size_t k = 0; k < row; ++k)
      if (lw[k] != 0.0) var += lw[k] * (cond_var[k] + (lambda[k] - mu) * (lambda[k] - mu));
    variance_out[i] = static_cast<float>(var / sum);
  });
}

Gmm merge(const Gmm& a, const Gmm& b) {
  validate(a);
  validate(b);
  Gmm out;
  out.support_size = checked::add<std::uint64_t>(a.support_size, b.support_size, "merged support size");
  // Support 0 means unknown. Weighing a known count against an unknown one
  // would be a guess (the old rule gave the unknown model weight 0 and so
  // dropped it silently); two unknowns count equally.
  const bool a_known = a.support_size > 0, b_known = b.support_size > 0;
  require(a_known == b_known, ErrorCode::InvalidArgument,
          std::string("merge: model ") + (a_known ? "b" : "a") + " has support size 0 (unknown) and model " +
              (a_known ? "a" : "b") + " has " + std::to_string(a_known ? a.support_size : b.support_size) +
              ": the weights cannot be combined; give both models their number of points (or neither)");
  const double sa = static_cast<double>(a.support_size), sb = static_cast<double>(b.support_size);
  const double fa = a_known ? sa / (sa + sb) : 0.5;
  const double fb = a_known ? sb / (sa + sb) : 0.5;
  out.weights.reserve(a.size() + b.size());
  for (float w : a.weights) out.weights.push_back(static_cast<float>(w * fa));
  for (float w : b.weights) out.weights.push_back(static_cast<float>(w * fb));
  out.means = a.means;
  out.means.insert(out.means.end(), b.means.begin(), b.means.end());
  out.covariances = a.covariances;
  out.covariances.insert(out.covariances.end(), b.covariances.begin(), b.covariances.end());
  return out;
}

Gmm transform(const Gmm& gmm, const std::array<double, 16>& pose) {
  validate(gmm);
  const std::string pose_problem = rigid_pose_error(pose);
  require(pose_problem.empty(), ErrorCode::InvalidArgument, "pose: " + pose_problem);
  const Eigen::Matrix4d t = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(pose.data());
  const Mat3 r = t.topLeftCorner<3, 3>();
  // Acting on (x, y, z, g) with the block-diagonal [R 0; 0 1].
  Mat4 a = Mat4::Identity();
  a.topLeftCorner<3, 3>() = r;
  Eigen::Vector4d shift = Eigen::Vector4d::Zero();
  shift.head<3>() = t.topRightCorner<3, 1>();
  Gmm out = gmm;
  for (std::size_t k = 0; k < gmm.size(); ++k) {
    const Eigen::Vector4d mu = a * mean_of(gmm, k) + shift;
    Mat4 c = a * covariance_of(gmm, k) * a.transpose();
    c = 0.5 * (c + c.transpose());
    for (int i = 0; i < 4; ++i) out.means[4 * k + i] = static_cast<float>(mu[i]);
    for (int i = 0; i < 16; ++i) out.covariances[16 * k + i] = static_cast<float>(c(i / 4, i % 4));
    // A finite pose can still move a mean out of float32 range (a translation
    // of 1e39): an error here rather than a model that no later call accepts.
    // (Messages are built only on failure: a map has tens of thousands of components.)
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(out.means[4 * k + i]))
        throw Error(ErrorCode::InvalidArgument, "pose moves the mean of component " + std::to_string(k) +
                                                    " to coordinate " + std::to_string(i) + " = " +
                                                    checked::exact(mu[i]) + ", beyond the float32 range");
    }
    for (int i = 0; i < 16; ++i) {
      if (!std::isfinite(out.covariances[16 * k + i]))
        throw Error(ErrorCode::InvalidArgument, "pose makes the covariance of component " + std::to_string(k) +
                                                    " non-finite in float32 (entry " + std::to_string(i) + " = " +
                                                    checked::exact(c(i / 4, i % 4)) + ")");
    }
  }
  return out;
}

std::size_t paper_model_bytes(const Gmm& gmm) { return 4 * gmm.size() * (1 + 10 + 4); }

}  // namespace sogmm
