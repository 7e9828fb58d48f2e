// Point-to-model registration (sogmm/registration.hpp).
#include "sogmm/registration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "finite_rows.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "registration_candidates.hpp"
#include "registration_kernel.hpp"
#include "sogmm/component_index.hpp"
#include "sogmm/error.hpp"
#include "sogmm/model.hpp"
#include "sogmm/options.hpp"

namespace sogmm {

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

constexpr double kLog2Pi = 1.8378770664093453;
// exp(x) rounds to +0 for x <= kExpZero (its smallest subnormal is
// exp(-745.13)).
constexpr double kExpZero = -746.0;
// Items per partial sum: fixed, so sums do not depend on threads. A model
// source has few items, each costing a 3 x 3 factor per component pair:
// smaller blocks let every thread work. A point source's coarsest level
// scores 768 points of a 12k-point frame (at least kCoarsePoints = 512):
// blocks of 128 split it 3 + 3 over 2 threads (256 gave 3 blocks, 2 + 1, so
// one thread idled a third of that level).
constexpr std::size_t kBlock = 128;
constexpr std::size_t kModelBlock = 16;
// The fewest points a coarse level scores. Every 16th of a 12k-point frame
// (768) held the loop frames of the README's speed line (the same errors as
// every 4th, 30-32 against 59 ms of CPU a call); 169 of the 2.7k points of
// the one-wall frame of the tracking tests left the slide along the wall
// still moving at the iteration cap (NotConverged, not Degenerate).
constexpr std::size_t kCoarsePoints = 512;
// How far (metres, per axis) a point may move before its candidate
// components are looked up again (detail::CandidateCache): a level's first
// steps move it by centimetres, its last ones by fractions of a millimetre.
constexpr double kCandidateMargin = 0.01;

// One component as a level scores it: the (conditional) spatial Gaussian and
// the constant terms of its log-density.
struct Component {
  Eigen::Vector3d mu;       // spatial mean
  Eigen::Matrix3d prec;     // inverse of the (conditional, smoothed) spatial covariance
  double log_norm = 0.0;    // log((1 - eps) pi_k) - log det(2 pi Sigma) / 2
  Eigen::Vector3d gain;     // use_gray: Sigma_xg / s_gg (conditional mean slope); else 0
  double mu_g = 0.0, inv_sgg = 0.0, log_norm_g = 0.0;  // use_gray: the gray marginal
  Eigen::Matrix4d cov;      // the smoothed 4-D covariance (a model source adds its own to it)
  double mu_gray = 0.0;     // the gray mean
  double log_weight = 0.0;  // log((1 - eps) pi_k)
};

// The target smoothed by s: its components, their boxes (an index over them
// where a level looks components up), and each component's record for the
// point source's pair kernel.
struct Level {
  std::vector<Component> comps;
  std::vector<Box3> boxes;  // component_box at ComponentIndex's default 3 sigma
  ComponentIndex index;     // built when asked for
  std::vector<double> records;  // detail::kPairRecord per component
};

// Component k's record (registration_kernel.hpp's fields).
void fill_record(const Component& k, double* r) {
  using namespace detail;
  for (int d = 0; d < 3; ++d) {
    r[kMuX + d] = k.mu(d);
    r[kGainX + d] = k.gain(d);
  }
  // The precision is symmetric up to the solve's rounding: its mean.
  r[kP00] = k.prec(0, 0);
  r[kP01] = 0.5 * (k.prec(0, 1) + k.prec(1, 0));
  r[kP02] = 0.5 * (k.prec(0, 2) + k.prec(2, 0));
  r[kP11] = k.prec(1, 1);
  r[kP12] = 0.5 * (k.prec(1, 2) + k.prec(2, 1));
  r[kP22] = k.prec(2, 2);
  r[kMuGray] = k.mu_g;
  r[kInvSgg] = k.inv_sgg;
  r[kLogNorm] = k.log_norm;
  r[kLogNormGray] = k.log_norm_g;
}

// A record's precision as a matrix.
Eigen::Matrix3d record_precision(const double* r) {
  using namespace detail;
  Eigen::Matrix3d p;
  p << r[kP00], r[kP01], r[kP02], r[kP01], r[kP11], r[kP12], r[kP02], r[kP12], r[kP22];
  return p;
}

// `indexed`: also build the index (a point source looks up only the
// coarsest level's, through detail::CandidateCache; finer levels need boxes).
// The components are prepared on the team (each its own; an index build is
// one thread's): a serial part of every call that 2 threads cannot halve.
Level make_level(const Gmm& gmm, double s, double eps, bool use_gray, bool indexed, int team) {
  Level level;
  Gmm smoothed = gmm;
  const std::size_t count = gmm.size();
  level.comps.resize(count);
  level.boxes.resize(count);
  level.records.assign(count * detail::kPairRecord, 0.0);
  // 0: component m's spatial covariance is not positive definite (reported
  // for the lowest such m after the loop, whatever the team).
  std::vector<std::uint8_t> ok(count, 1);
  constexpr std::size_t kChunk = 64;
  detail::parallel_for((count + kChunk - 1) / kChunk, team, 1, [&](std::size_t chunk, int) {
    for (std::size_t m = chunk * kChunk; m < std::min(count, (chunk + 1) * kChunk); ++m) {
      const float* c = gmm.covariance(m);
      Eigen::Matrix4d cov;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) cov(i, j) = 0.5 * (double(c[4 * i + j]) + double(c[4 * j + i]));
      for (int i = 0; i < 3; ++i) {
        cov(i, i) += s * s;
        smoothed.covariances[16 * m + 5 * i] = static_cast<float>(cov(i, i));
      }
      Component& k = level.comps[m];
      const float* mu = gmm.mean(m);
      k.mu = Eigen::Vector3d(mu[0], mu[1], mu[2]);
      k.cov = cov;
      k.mu_gray = mu[3];
      k.log_weight = std::log((1.0 - eps) * double(gmm.weights[m]));
      Eigen::Matrix3d spatial = cov.topLeftCorner<3, 3>();
      k.gain.setZero();
      k.log_norm = std::log((1.0 - eps) * double(gmm.weights[m]));
      if (use_gray) {
        const double sgg = cov(3, 3);
        k.gain = cov.block<3, 1>(0, 3) / sgg;
        spatial -= k.gain * cov.block<1, 3>(3, 0);
        k.mu_g = mu[3];
        k.inv_sgg = 1.0 / sgg;
        k.log_norm_g = -0.5 * (kLog2Pi + std::log(sgg));
      }
      const Eigen::LLT<Eigen::Matrix3d> llt(spatial);
      if (!(llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() > 0)) {
        ok[m] = 0;
        continue;
      }
      k.prec = llt.solve(Eigen::Matrix3d::Identity());
      k.log_norm -= 0.5 * (3 * kLog2Pi) + llt.matrixLLT().diagonal().array().log().sum();
      level.boxes[m] = component_box(smoothed, m, ComponentIndex::kDefaultSigmas);
      fill_record(k, level.records.data() + m * detail::kPairRecord);
    }
  });
  const auto bad = std::find(ok.begin(), ok.end(), std::uint8_t{0});
  require(bad == ok.end(), ErrorCode::Numeric,
          "registration: the spatial covariance of target component " +
              std::to_string(bad - ok.begin()) + " is not positive definite");
  if (indexed) level.index.build(smoothed);
  return level;
}

// Level l's smoothing: coarse_sigma halved per level, 0 on the last.
double level_sigma(const RegistrationOptions& o, std::int32_t l) {
  return l + 1 == o.levels ? 0.0 : o.coarse_sigma * std::ldexp(1.0, -l);
}

}  // namespace

// A target's levels and outlier density for one set of level options.
struct RegistrationTarget::Prepared {
  std::vector<Level> levels;
  double log_outlier = 0.0;  // log(eps / V), V the target's 3-sigma box
  // What the levels depend on (RegistrationTarget::prepared_for).
  std::int32_t level_count = 0;
  double coarse_sigma = 0.0, outlier_ratio = 0.0;
  bool use_gray = false;
};

namespace {

// Builds `target`'s levels for `o` (both validated by the caller: they are
// a call's first errors; a source's come next, then a level's non-positive-
// definite component). `index_all`: every level gets an index (model sources
// look each level's up); otherwise only the coarsest (a point source's
// candidate cache is built on it; finer levels filter by their boxes).
std::unique_ptr<RegistrationTarget::Prepared> prepare(const Gmm& target, const RegistrationOptions& o, int team,
                                                      bool index_all) {
  auto p = std::make_unique<RegistrationTarget::Prepared>();
  p->level_count = o.levels;
  p->coarse_sigma = o.coarse_sigma;
  p->outlier_ratio = o.outlier_ratio;
  p->use_gray = o.use_gray;
  const double eps = o.outlier_ratio;
  // The outlier density: uniform over the target's 3-sigma box.
  Box3 span = component_box(target, 0, 3.0);
  for (std::size_t m = 1; m < target.size(); ++m) {
    const Box3 b = component_box(target, m, 3.0);
    for (int k = 0; k < 3; ++k) {
      span.lo[k] = std::min(span.lo[k], b.lo[k]);
      span.hi[k] = std::max(span.hi[k], b.hi[k]);
    }
  }
  double volume = 1.0;
  for (int k = 0; k < 3; ++k) volume *= std::max(span.hi[k] - span.lo[k], 1e-3);
  p->log_outlier = eps > 0 ? std::log(eps / volume) : -std::numeric_limits<double>::infinity();
  p->levels.reserve(static_cast<std::size_t>(o.levels));
  for (std::int32_t l = 0; l < o.levels; ++l)
    p->levels.push_back(make_level(target, level_sigma(o, l), eps, o.use_gray, l == 0 || index_all, team));
  return p;
}

// The sums one pass over the points gives at a pose.
struct Sums {
  Mat6 hessian = Mat6::Zero();      // sum w J^T P J (Gauss-Newton)
  Vec6 gradient = Vec6::Zero();     // sum w J^T P r (of the cost)
  Mat6 spread = Mat6::Zero();       // sum_i (sum_k w G G^T - Gbar Gbar^T) (Louis' correction)
  double log_likelihood = 0.0;
  double inliers = 0.0;
  double mahalanobis = 0.0;         // over inliers
  void add(const Sums& o) {
    hessian += o.hessian;
    gradient += o.gradient;
    spread += o.spread;
    log_likelihood += o.log_likelihood;
    inliers += o.inliers;
    mahalanobis += o.mahalanobis;
  }
};

// A thread's pairs (source item, candidate component) as arrays: a model
// source's item at a time, a point source's block at a time (the pair
// kernel's inputs and outputs).
struct Scratch {
  std::vector<std::uint32_t> ids;
  std::vector<double> x, y, z, gray;  // a point source: the pair's point
  std::vector<double> pair_top;       // a point source: the pair's point's largest log-density
  std::vector<double> term;  // each pair's log-density, then exp(it - the largest)
  std::vector<double> pr_x, pr_y, pr_z, quad;  // P r and r^T P r
  // A point source with depth noise: each pair's noise axis u, P u and
  // 1 / (1 + u^T P u) (registration_kernel.hpp).
  std::vector<double> ux, uy, uz, pu_x, pu_y, pu_z, shrink;
  std::vector<Eigen::Matrix3d> prec;  // a model source: each pair's own precision
  std::vector<std::size_t> first;     // a point source: each point's first pair, then the end
  std::vector<Eigen::Vector3d> moved;  // a point source: the block's points at the pose
  std::vector<std::uint32_t> query;   // CandidateCache::near's scratch
  std::vector<double> top;            // a point source: each point's largest log-density
  // The noise axes only with depth noise: the plain kernel touches none.
  void resize(std::size_t count, bool noise_axes = false) {
    for (auto* v : {&x, &y, &z, &gray, &pair_top, &term, &pr_x, &pr_y, &pr_z, &quad}) v->resize(count);
    if (noise_axes)
      for (auto* v : {&ux, &uy, &uz, &pu_x, &pu_y, &pu_z, &shrink}) v->resize(count);
  }
};

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v(2), v(1), v(2), 0, -v(0), -v(1), v(0), 0;
  return s;
}

// The log-density of a model source's component (transformed mean x, gray,
// covariance `spread4` in the target frame) under target component k: the
// Gaussian-Gaussian overlap integral N(x; mu_k, Sigma_k + S), split as the
// point case is (gray marginal, then the conditional spatial Gaussian).
// Sets the residual and the pair's spatial precision.
double pair_log_density(const Component& k, const Eigen::Vector3d& x, double gray, const Eigen::Matrix4d& spread4,
                        bool use_gray, Eigen::Vector3d& r, Eigen::Matrix3d& prec) {
  const Eigen::Matrix4d c = k.cov + spread4;
  Eigen::Matrix3d spatial = c.topLeftCorner<3, 3>();
  r = x - k.mu;
  double lp = k.log_weight;
  if (use_gray) {
    const double cgg = c(3, 3);
    const Eigen::Vector3d gain = c.block<3, 1>(0, 3) / cgg;
    spatial -= gain * c.block<1, 3>(3, 0);
    const double dg = gray - k.mu_gray;
    r -= gain * dg;
    lp += -0.5 * (kLog2Pi + std::log(cgg)) - 0.5 * dg * dg / cgg;
  }
  // Sigma_k + S is positive definite when Sigma_k is (S is positive
  // semidefinite), but rounding can still break a near-singular sum.
  const Eigen::LLT<Eigen::Matrix3d> llt(spatial);
  require(llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() > 0, ErrorCode::Numeric,
          "registration: a target component plus a source component's covariance is not positive definite");
  prec = llt.solve(Eigen::Matrix3d::Identity());
  lp -= 0.5 * (3 * kLog2Pi) + llt.matrixLLT().diagonal().array().log().sum();
  return lp - 0.5 * r.dot(prec * r);
}

// The components a model source's item tests: those whose box meets the
// source component's own 3-sigma box, a superset of those within 3 sigma of
// the sum of both covariances (sqrt(a + b) <= sqrt(a) + sqrt(b) per axis).
void model_candidates(const Level& level, const Eigen::Vector3d& x, const Eigen::Matrix4d& spread4,
                      std::vector<std::uint32_t>& ids) {
  Box3 box;
  for (int d = 0; d < 3; ++d) {
    const double half = 3.0 * std::sqrt(std::max(spread4(d, d), 0.0));
    box.lo[d] = x(d) - half;
    box.hi[d] = x(d) + half;
  }
  level.index.query_box(box, ids);
}

// A model source's item (its component's transformed mean x, gray, and
// covariance `spread4` in the target frame) against the components s.ids:
// each pair's log-density, P r, r^T P r and own precision P into s.
// (A point source's come from the pair kernel.)
void model_pairs(const Level& level, const Eigen::Vector3d& x, double gray, const Eigen::Matrix4d& spread4,
                 bool use_gray, Scratch& s) {
  const std::size_t count = s.ids.size();
  s.resize(count);
  s.prec.resize(count);
  for (std::size_t j = 0; j < count; ++j) {
    Eigen::Vector3d r;
    s.term[j] = pair_log_density(level.comps[s.ids[j]], x, gray, spread4, use_gray, r, s.prec[j]);
    const Eigen::Vector3d pr = s.prec[j] * r;
    s.pr_x[j] = pr(0);
    s.pr_y[j] = pr(1);
    s.pr_z[j] = pr(2);
    s.quad[j] = r.dot(pr);
  }
}

// The largest of the outlier's and pairs [from, to)'s log-densities (-inf:
// no component's box holds the item and there is no outlier term).
double top_of(const Scratch& s, std::size_t from, std::size_t to, double log_outlier) {
  double top = log_outlier;
  for (std::size_t j = from; j < to; ++j) top = std::max(top, s.term[j]);
  return top;
}

// One source item's share, counted `weight` times: x is the transformed
// point (a model source: its component's mean), c the perturbation centre,
// pairs [from, to) of s its candidates (ascending ids) with their terms
// exp(log-density - top) in s.term (top: top_of's, finite), P r and r^T P r,
// and precision_of(j) pair j's precision P. Each responsibility is its term
// over their total: one exp per pair, not two.
template <class PrecisionOf>
void score_item(Scratch& s, std::size_t from, std::size_t to, double top, PrecisionOf precision_of,
                const Eigen::Vector3d& x, double weight, const Eigen::Vector3d& c, double log_outlier, bool spread,
                Sums& out) {
  const double* term = s.term.data();
  const double term_out = std::exp(log_outlier - top);
  double total = term_out;
  for (std::size_t j = from; j < to; ++j) total += term[j];
  const double lse = top + std::log(total);
  const double inv_total = 1.0 / total;
  out.log_likelihood += weight * lse;
  const double w_out = term_out * inv_total;
  const bool inlier = w_out < 0.5;
  if (inlier) out.inliers += weight;
  // J = [-[a]x, I] with a = x - c is the same for every component of the
  // point: sum the weighted precisions W and precision-weighted residuals
  // first, then one J^T W J. (A model source's covariance is held at the
  // current pose within a step: the Gauss-Newton step moves its mean.)
  const Eigen::Vector3d a = x - c;
  // Louis' spread, sum_k w G G^T - Gbar Gbar^T with G = J^T P r, is
  // J^T (sum_k w (P r)(P r)^T - (W r)(W r)^T) J: a 3 x 3 sum per pair and
  // one product with J per point. It is summed only when asked for: most
  // evaluations do not use it.
  Eigen::Matrix3d wprr = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d wp = Eigen::Matrix3d::Zero();
  Eigen::Vector3d wpr = Eigen::Vector3d::Zero();
  for (std::size_t j = from; j < to; ++j) {
    // Responsibilities below 1e-12 are dropped.
    const double w = term[j] * inv_total;
    if (w < 1e-12) continue;
    const Eigen::Vector3d pr(s.pr_x[j], s.pr_y[j], s.pr_z[j]);
    wp += w * precision_of(j);
    wpr += w * pr;
    if (inlier) out.mahalanobis += weight * w * s.quad[j];
    if (spread) wprr.noalias() += (w * pr) * pr.transpose();
  }
  // With S = [a]x (S v = a x v, S^T = -S), J = [-S, I] and a symmetric C:
  // J^T C J = [-S C S, S C; (S C)^T, C] and J^T v = [a x v; v].
  const Eigen::Matrix3d sa = skew(a);
  const auto add_jtcj = [&](Mat6& to, const Eigen::Matrix3d& cm) {
    const Eigen::Matrix3d m = sa * cm;
    to.topLeftCorner<3, 3>().noalias() -= weight * (m * sa);
    to.topRightCorner<3, 3>().noalias() += weight * m;
    to.bottomLeftCorner<3, 3>().noalias() += weight * m.transpose();
    to.bottomRightCorner<3, 3>().noalias() += weight * cm;
  };
  add_jtcj(out.hessian, wp);
  out.gradient.head<3>() += weight * a.cross(wpr);
  out.gradient.tail<3>() += weight * wpr;
  if (spread) add_jtcj(out.spread, wprr - wpr * wpr.transpose());
}

// The pose as R, t.
struct Rigid {
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
};

Rigid rigid_of(const std::array<double, 16>& p) {
  Rigid g;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) g.r(i, j) = p[4 * i + j];
    g.t(i) = p[4 * i + 3];
  }
  return g;
}

std::array<double, 16> array_of(const Rigid& g) {
  std::array<double, 16> p{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) p[4 * i + j] = g.r(i, j);
    p[4 * i + 3] = g.t(i);
  }
  p[15] = 1.0;
  return p;
}

// The Gauss-Newton (EM) step: the responsibilities held, so the curvature
// is the complete-data information sum w J^T P J. It converges linearly, and
// slowly along directions the scene barely constrains (a wall's slide), where
// most of that information is missing.
Vec6 gauss_newton_step(const Sums& sums, double scale) {
  return -(sums.hessian + 1e-9 * scale * Mat6::Identity()).ldlt().solve(sums.gradient);
}

// The Newton step on the log-likelihood itself: its curvature is the observed
// information, hessian - spread (Louis' formula), so it converges
// quadratically where the Gauss-Newton step converges linearly (the synthetic
// loop's frames took 9-10 iterations instead of 18-30). Only where the
// observed information, rotation scaled by the source's radius, is positive
// definite with its eigenvalues within kNewtonMinEigenRatio of the largest:
// along a direction held more weakly than that, a Newton step is gradient
// noise amplified 1e4-fold and more, and on a wall the coarse levels
// wandered along the slide to max_iter. Elsewhere the Gauss-Newton step. A
// direction held weakly but above that (a wall view's slide, under the
// default Degenerate ratio of 1e-3) is where Newton gains most: loop frame
// 150's finest level took 3 steps instead of 6. The step's length is also
// capped at kNewtonStepCap Gauss-Newton steps: the observed information at
// the start of a level holds only near it, and on that wall view the
// uncapped step overshot the slide 8-fold.
constexpr double kNewtonMinEigenRatio = 1e-4;
constexpr double kNewtonStepCap = 3.0;
Vec6 newton_step(const Sums& sums, double scale, double radius) {
  const Vec6 gauss_newton = gauss_newton_step(sums, scale);
  Vec6 d;
  d << radius, radius, radius, 1, 1, 1;
  const Mat6 observed = sums.hessian - sums.spread;
  const Mat6 scaled = d.cwiseInverse().asDiagonal() * (0.5 * (observed + observed.transpose())) * d.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(scaled, Eigen::EigenvaluesOnly);
  const Vec6 ev = eig.eigenvalues();
  if (!(ev.minCoeff() > kNewtonMinEigenRatio * ev.maxCoeff())) return gauss_newton;
  Vec6 step = -(0.5 * (observed + observed.transpose())).ldlt().solve(sums.gradient);
  const auto length = [radius](const Vec6& v) { return v.head<3>().norm() * radius + v.tail<3>().norm(); };
  const double cap = kNewtonStepCap * length(gauss_newton);
  if (length(step) > cap) step *= cap / length(step);
  return step.allFinite() ? step : gauss_newton;
}

// pose <- exp(step) pose, the rotation about the source's transformed centroid.
void apply_step(const Vec6& step, const Eigen::Vector3d& centroid, Rigid& pose) {
  const Eigen::Vector3d w = step.head<3>(), v = step.tail<3>();
  const double angle = w.norm();
  const Eigen::Matrix3d rot =
      angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d c = pose.r * centroid + pose.t;
  pose.r = rot * pose.r;
  pose.t = rot * (pose.t - c) + c + v;
}

}  // namespace

void validate(const RegistrationOptions& o) {
  require_option(OptionKey::REGISTRATION_MAX_ITER, std::int64_t{o.max_iter}, "registration max_iter");
  require_option(OptionKey::REGISTRATION_TOL, o.tol, "registration tol");
  require_option(OptionKey::REGISTRATION_OUTLIER_RATIO, o.outlier_ratio, "registration outlier_ratio");
  require_option(OptionKey::REGISTRATION_USE_GRAY, std::int64_t{o.use_gray}, "registration use_gray");
  require_option(OptionKey::REGISTRATION_LEVELS, std::int64_t{o.levels}, "registration levels");
  require_option(OptionKey::REGISTRATION_COARSE_SIGMA, o.coarse_sigma, "registration coarse_sigma");
  require_option(OptionKey::REGISTRATION_MIN_INLIER_RATIO, o.min_inlier_ratio, "registration min_inlier_ratio");
  require_option(OptionKey::REGISTRATION_DEGENERACY_RATIO, o.degeneracy_ratio, "registration degeneracy_ratio");
  require_option(OptionKey::REGISTRATION_MIN_POINTS, o.min_points, "registration min_points");
  require_option(OptionKey::REGISTRATION_DEPTH_NOISE, o.depth_noise, "registration depth_noise");
}

const char* status_name(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::Converged: return "converged";
    case RegistrationStatus::NotConverged: return "not converged";
    case RegistrationStatus::LowFitness: return "low fitness";
    case RegistrationStatus::Degenerate: return "degenerate";
  }
  return "unknown";
}

namespace {

// What is registered: n rows of (x, y, z, gray); a model source adds each
// row's 4 x 4 covariance and the number of points it stands for.
struct Source {
  const float* rows = nullptr;
  std::size_t n = 0;
  const float* covariances = nullptr;  // null: points
  std::vector<double> weights;         // empty: each row counts once
  double weight(std::size_t i) const { return weights.empty() ? 1.0 : weights[i]; }
};

RegistrationResult register_source(const RegistrationTarget::Prepared& target, const Source& src,
                                   const std::array<double, 16>& init, const RegistrationOptions& options,
                                   int threads, const ProgressSink& progress) {
  const float* points = src.rows;
  const std::size_t n = src.n;
  const bool model_source = src.covariances != nullptr;
  const ProgressScope scope(progress);
  const int team = detail::team_size(threads);
  const double log_outlier = target.log_outlier;
  const double depth_noise = model_source ? 0.0 : options.depth_noise;
  const bool noisy = depth_noise > 0;

  // The source's centroid and RMS radius (pose invariant: the step's scale);
  // a model source's are those of the points it stands for.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double total_weight = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    centroid += src.weight(i) * Eigen::Vector3d(points[4 * i], points[4 * i + 1], points[4 * i + 2]);
    total_weight += src.weight(i);
  }
  centroid /= total_weight;
  double radius2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double spread2 = (Eigen::Vector3d(points[4 * i], points[4 * i + 1], points[4 * i + 2]) - centroid).squaredNorm();
    if (model_source) {
      const float* c = src.covariances + 16 * i;
      spread2 += double(c[0]) + double(c[5]) + double(c[10]);
    }
    radius2 += src.weight(i) * spread2;
  }
  const double radius = std::max(std::sqrt(radius2 / total_weight), 1e-6);

  std::vector<Scratch> scratch(static_cast<std::size_t>(team));
  std::vector<Sums> partial;
  const detail::RegistrationKernels& kernels = detail::registration_kernels();
  // Every `stride`-th point (coarse levels need fewer: their targets are smooth).
  // A point's candidates: `cands` (built on the coarsest level) filtered by
  // `level`'s own boxes.
  auto evaluate = [&](const Level& level, detail::CandidateCache& cands, const Rigid& pose, bool spread,
                      std::size_t stride) {
    const Eigen::Vector3d c = pose.r * centroid + pose.t;
    const std::size_t block = model_source ? kModelBlock : kBlock;
    const std::size_t used = (n + stride - 1) / stride, blocks = (used + block - 1) / block;
    partial.assign(blocks, Sums{});
    detail::parallel_for(blocks, team, 1, [&](std::size_t blk, int thread) {
      Sums s;
      Scratch& sc = scratch[static_cast<std::size_t>(thread)];
      const std::size_t first = blk * block, last = std::min(used, (blk + 1) * block);
      if (!model_source) {
        // The block's points moved once and their pairs listed (the
        // candidates whose box on this level holds the point, kept without
        // a branch per candidate), scored by the kernel in one pass, then
        // summed point by point.
        sc.first.clear();
        sc.moved.clear();
        std::size_t count = 0;
        for (std::size_t v = first; v < last; ++v) {
          const float* p = points + 4 * v * stride;
          const Eigen::Vector3d x = pose.r * Eigen::Vector3d(p[0], p[1], p[2]) + pose.t;
          const std::vector<std::uint32_t>& near = cands.near(v * stride, x, sc.query);
          sc.first.push_back(count);
          sc.moved.push_back(x);
          if (sc.ids.size() < count + near.size()) {
            sc.ids.resize(2 * (count + near.size()));
            sc.resize(sc.ids.size(), noisy);
          }
          const double xyz[3] = {x(0), x(1), x(2)};
          // The depth-noise axis: a depth error e moves the point by e p / z
          // along its ray, so sigma_z = depth_noise z^2 gives u = depth_noise
          // z R p (none for a point not in front of the sensor).
          const Eigen::Vector3d u =
              noisy && p[2] > 0 ? Eigen::Vector3d(depth_noise * double(p[2]) * (x - pose.t)) : Eigen::Vector3d::Zero();
          for (std::uint32_t id : near) {
            sc.ids[count] = id;
            sc.x[count] = xyz[0];
            sc.y[count] = xyz[1];
            sc.z[count] = xyz[2];
            sc.gray[count] = p[3];
            if (noisy) {  // only with noise: the plain kernel reads none of them
              sc.ux[count] = u(0);
              sc.uy[count] = u(1);
              sc.uz[count] = u(2);
            }
            // Box3::contains without a branch per bound (about half the
            // candidates fail, unpredictably).
            const Box3& b = level.boxes[id];
            count += (xyz[0] >= b.lo[0]) & (xyz[0] <= b.hi[0]) & (xyz[1] >= b.lo[1]) & (xyz[1] <= b.hi[1]) &
                     (xyz[2] >= b.lo[2]) & (xyz[2] <= b.hi[2]);
          }
        }
        sc.first.push_back(count);
        kernels.pairs(level.records.data(),
                      {sc.ids.data(), sc.x.data(), sc.y.data(), sc.z.data(), sc.gray.data(),
                       noisy ? sc.ux.data() : nullptr, sc.uy.data(), sc.uz.data(), sc.term.data(), sc.pr_x.data(),
                       sc.pr_y.data(), sc.pr_z.data(), sc.quad.data(), sc.pu_x.data(), sc.pu_y.data(),
                       sc.pu_z.data(), sc.shrink.data()},
                      count);
        // Each point's largest log-density beside its pairs, then every
        // pair's term in one pass.
        sc.top.resize(last - first);
        for (std::size_t v = 0; v < last - first; ++v) {
          sc.top[v] = top_of(sc, sc.first[v], sc.first[v + 1], log_outlier);
          std::fill(sc.pair_top.begin() + sc.first[v], sc.pair_top.begin() + sc.first[v + 1], sc.top[v]);
        }
        kernels.terms(sc.term.data(), sc.pair_top.data(), sc.term.data(), count);
        // With depth noise a pair's precision is the record's less the
        // kernel's rank-one update.
        const auto precision_of = [&](std::size_t j) {
          Eigen::Matrix3d prec = record_precision(level.records.data() + std::size_t{detail::kPairRecord} * sc.ids[j]);
          if (noisy) {
            const Eigen::Vector3d pu(sc.pu_x[j], sc.pu_y[j], sc.pu_z[j]);
            prec.noalias() -= sc.shrink[j] * pu * pu.transpose();
          }
          return prec;
        };
        for (std::size_t v = 0; v < last - first; ++v) {
          // As for a model source: an item with no density is left out.
          if (sc.top[v] == -std::numeric_limits<double>::infinity()) continue;
          score_item(sc, sc.first[v], sc.first[v + 1], sc.top[v], precision_of, sc.moved[v], 1.0, c, log_outlier,
                     spread, s);
        }
        partial[blk] = s;
        return;
      }
      for (std::size_t v = first; v < last; ++v) {
        const std::size_t i = v * stride;
        const float* p = points + 4 * i;
        const Eigen::Vector3d x = pose.r * Eigen::Vector3d(p[0], p[1], p[2]) + pose.t;
        // The component's covariance in the target frame: diag(R, 1) S diag(R, 1)^T.
        Eigen::Matrix4d cov;
        const float* f = src.covariances + 16 * i;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) cov(a, b) = 0.5 * (double(f[4 * a + b]) + double(f[4 * b + a]));
        Eigen::Matrix4d rot = Eigen::Matrix4d::Identity();
        rot.topLeftCorner<3, 3>() = pose.r;
        const Eigen::Matrix4d moved = rot * cov * rot.transpose();
        model_candidates(level, x, moved, sc.ids);
        model_pairs(level, x, p[3], moved, options.use_gray, sc);
        // No component's box holds the item and no outlier term (outlier_ratio
        // 0): it has no density to move towards and is left out of every sum
        // (not an inlier), instead of making them NaN.
        const double top = top_of(sc, 0, sc.ids.size(), log_outlier);
        if (top == -std::numeric_limits<double>::infinity()) continue;
        // exp of an exponent below -746 is +0 (and costs libm's slow
        // underflow path): such a term adds nothing, so it is set to 0
        // without calling exp.
        for (double& e : sc.term) e = e - top > kExpZero ? std::exp(e - top) : 0.0;
        score_item(sc, 0, sc.ids.size(), top, [&](std::size_t j) { return sc.prec[j]; }, x, src.weight(i), c,
                   log_outlier, spread, s);
      }
      partial[blk] = s;
    });
    Sums total;
    for (const Sums& s : partial) total.add(s);
    return total;
  };

  RegistrationResult result;
  Rigid pose = rigid_of(init);
  const std::int32_t levels = options.levels;
  detail::progress_begin(Stage::Registration, std::uint64_t(levels) * std::uint64_t(options.max_iter));
  bool converged = false;
  std::optional<Sums> final_sums;
  // The candidate cache is built on the coarsest level's index.
  detail::CandidateCache cands(target.levels.front().index, model_source ? 0 : n, kCandidateMargin);
  for (std::int32_t l = 0; l < levels; ++l) {
    // Level l of L uses every 4^(L-1-l)-th point (at most 16x fewer), keeping
    // at least kCoarsePoints and min_points: the coarse levels only bring the
    // pose within the finest level's reach, which scores every point.
    std::size_t stride = model_source ? 1 : std::size_t{1} << std::min(2 * (levels - 1 - l), 4);
    const auto fewest = std::max<std::size_t>(kCoarsePoints, static_cast<std::size_t>(options.min_points));
    while (stride > 1 && n / stride < fewest) stride /= 2;
    const Level& level = target.levels[static_cast<std::size_t>(l)];
    converged = false;
    const bool finest = l + 1 == levels;
    for (std::int32_t it = 0; it < options.max_iter && !converged; ++it) {
      // A point source's steps use the observed information, so its
      // evaluations sum Louis' spread too.
      Sums sums = evaluate(level, cands, pose, !model_source, stride);
      ++result.iterations;
      detail::progress_event(std::uint64_t(result.iterations), sums.log_likelihood / (model_source ? total_weight : double((n + stride - 1) / stride)));
      const double scale = sums.hessian.diagonal().maxCoeff();
      if (!(scale > 0)) break;  // no point near the target: nothing to move towards
      // A model source's covariances are held at the current rotation within
      // a step, so its hessian - spread is not its objective's curvature
      // (Newton steps ended livingroom 0 -> 1 at 0.59 instead of 0.47 cm):
      // it takes Gauss-Newton steps.
      const Vec6 step = model_source ? gauss_newton_step(sums, scale)
                                     : newton_step(sums, scale, radius);
      if (!step.allFinite()) break;
      converged = step.tail<3>().norm() + step.head<3>().norm() * radius < options.tol;
      if (converged && finest && !model_source) {
        // This pose moves by less than tol: it is the answer, and these
        // sums (on the unsmoothed model, every point, with the spread) are
        // its final figures, which saves one evaluation of every point.
        final_sums = std::move(sums);
        break;
      }
      apply_step(step, centroid, pose);
    }
  }

  // The figures at the final pose, on the unsmoothed model.
  const Sums fin = final_sums ? *final_sums : evaluate(target.levels.back(), cands, pose, true, 1);
  const Mat6 info_c = fin.hessian - fin.spread;  // about the centroid c
  const Eigen::Vector3d c = pose.r * centroid + pose.t;
  // xi_origin = A xi_c with A = [I 0; [c]x I]: information_origin = A^-T info_c A^-1.
  Mat6 a_inv = Mat6::Identity();
  a_inv.bottomLeftCorner<3, 3>() = -skew(c);
  const Mat6 info = a_inv.transpose() * info_c * a_inv;
  Vec6 d;
  d << radius, radius, radius, 1, 1, 1;
  const Mat6 scaled = d.cwiseInverse().asDiagonal() * (0.5 * (info_c + info_c.transpose())) * d.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(scaled, Eigen::EigenvaluesOnly);
  const Vec6 ev = eig.eigenvalues().cwiseMax(0.0);
  const double top = ev.maxCoeff();
  result.eigen_ratio = top > 0 ? ev.minCoeff() / top : 0.0;
  for (int k = 0; k < 6; ++k)
    if (!(ev(k) > options.degeneracy_ratio * top)) ++result.unobservable;

  // Many small rotations multiplied: project R back onto the rotations so
  // that the answer passes rigid_pose_error as the next call's start.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(pose.r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  pose.r = svd.matrixU() * svd.matrixV().transpose();
  result.pose = array_of(pose);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) result.information[6 * i + j] = 0.5 * (info(i, j) + info(j, i));
  result.log_likelihood = fin.log_likelihood / total_weight;  // total_weight = n for points
  result.inlier_ratio = fin.inliers / total_weight;
  result.rmse = fin.inliers > 0 ? std::sqrt(fin.mahalanobis / (3.0 * fin.inliers)) : 0.0;
  if (!converged)
    result.status = RegistrationStatus::NotConverged;
  else if (result.inlier_ratio < options.min_inlier_ratio)
    result.status = RegistrationStatus::LowFitness;
  else if (result.unobservable > 0)
    result.status = RegistrationStatus::Degenerate;
  else
    result.status = RegistrationStatus::Converged;
  return result;
}

// The checks of a point source, before any preparation.
Source point_source(const float* points, std::size_t n, const std::array<double, 16>& init,
                    const RegistrationOptions& options) {
  const std::string pose_error = rigid_pose_error(init);
  require(pose_error.empty(), ErrorCode::InvalidArgument, "registration: the initial pose " + pose_error);
  require(n >= static_cast<std::uint64_t>(options.min_points), ErrorCode::InvalidData,
          "registration: " + std::to_string(n) + " source points, fewer than min_points = " +
              std::to_string(options.min_points));
  require(points != nullptr, ErrorCode::InvalidArgument, "registration: null points");
  detail::require_finite_rows(points, n, 4, "source points for registration");
  Source src;
  src.rows = points;
  src.n = n;
  return src;
}

// The checks of a model source, before any preparation: each component
// stands for its share of the points the model was fitted on (a model
// without a support size: one point per component).
Source model_source(const Gmm& source, const std::array<double, 16>& init, const RegistrationOptions& options) {
  require(source.size() > 0, ErrorCode::InvalidData, "registration: the source model has no component");
  validate(source);
  const std::string pose_error = rigid_pose_error(init);
  require(pose_error.empty(), ErrorCode::InvalidArgument, "registration: the initial pose " + pose_error);
  const double support = source.support_size > 0 ? double(source.support_size) : double(source.size());
  require(support >= double(options.min_points), ErrorCode::InvalidData,
          "registration: the source model stands for " + std::to_string(static_cast<std::uint64_t>(support)) +
              " points, fewer than min_points = " + std::to_string(options.min_points));
  Source src;
  src.rows = source.means.data();
  src.n = source.size();
  src.covariances = source.covariances.data();
  src.weights.resize(source.size());
  for (std::size_t j = 0; j < source.size(); ++j) src.weights[j] = double(source.weights[j]) * support;
  return src;
}

// `options` against the options `target` was prepared for.
void require_prepared_for(const RegistrationTarget& target, const RegistrationOptions& options) {
  validate(options);
  require(target.prepared_for(options), ErrorCode::InvalidArgument,
          "registration: the prepared target was made for other levels, coarse_sigma, outlier_ratio or use_gray");
}

// A RegistrationTarget's levels, checked as a call checks them first; every
// level indexed, for both kinds of source.
std::unique_ptr<RegistrationTarget::Prepared> checked_prepare(const Gmm& target, const RegistrationOptions& options,
                                                              int threads) {
  validate(options);
  validate(target);
  return prepare(target, options, detail::team_size(threads), true);
}

}  // namespace

RegistrationTarget::RegistrationTarget(const Gmm& target, const RegistrationOptions& options, int threads)
    : prepared_(checked_prepare(target, options, threads)) {}
RegistrationTarget::~RegistrationTarget() = default;
RegistrationTarget::RegistrationTarget(RegistrationTarget&&) noexcept = default;
RegistrationTarget& RegistrationTarget::operator=(RegistrationTarget&&) noexcept = default;

bool RegistrationTarget::prepared_for(const RegistrationOptions& o) const {
  const Prepared& p = *prepared_;
  return p.level_count == o.levels && p.coarse_sigma == o.coarse_sigma && p.outlier_ratio == o.outlier_ratio &&
         p.use_gray == o.use_gray;
}

RegistrationResult register_points(const Gmm& target, const float* points, std::size_t n,
                                   const std::array<double, 16>& init, const RegistrationOptions& options,
                                   int threads, const ProgressSink& progress) {
  validate(options);
  validate(target);
  const Source src = point_source(points, n, init, options);
  const auto prepared = prepare(target, options, detail::team_size(threads), false);
  return register_source(*prepared, src, init, options, threads, progress);
}

RegistrationResult register_points(const RegistrationTarget& target, const float* points, std::size_t n,
                                   const std::array<double, 16>& init, const RegistrationOptions& options,
                                   int threads, const ProgressSink& progress) {
  require_prepared_for(target, options);
  return register_source(target.prepared(), point_source(points, n, init, options), init, options, threads,
                         progress);
}

RegistrationResult register_model(const Gmm& target, const Gmm& source, const std::array<double, 16>& init,
                                  const RegistrationOptions& options, int threads, const ProgressSink& progress) {
  validate(options);
  validate(target);
  const Source src = model_source(source, init, options);
  const auto prepared = prepare(target, options, detail::team_size(threads), true);
  return register_source(*prepared, src, init, options, threads, progress);
}

RegistrationResult register_model(const RegistrationTarget& target, const Gmm& source,
                                  const std::array<double, 16>& init, const RegistrationOptions& options,
                                  int threads, const ProgressSink& progress) {
  require_prepared_for(target, options);
  return register_source(target.prepared(), model_source(source, init, options), init, options, threads,
                         progress);
}

}  // namespace sogmm
