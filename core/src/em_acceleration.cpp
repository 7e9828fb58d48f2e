// SQUAREM-accelerated EM: the S3 step with its two safeguards (see
// em_acceleration.hpp).
#include "em_acceleration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "parallel.hpp"

namespace sogmm::detail {
namespace {

// The step-length schedule of the reference implementation (R package
// SQUAREM, squarem1's defaults): a is capped at step_max, which starts at 1
// (the first cycle is plain EM, while the k-means++ start still moves a
// lot), grows x4 each time the cap binds and shrinks /4 (not below 1) when a
// capped step is rejected.
constexpr double kStepMax0 = 1.0;
constexpr double kStepFactor = 4.0;
// A step length this close to 1 is the plain step (t2 itself).
constexpr double kPlain = 1.01;
// Log-weights below this (a component without weight, e.g. a warm start's
// zero weights at -1e30) make differences that mean nothing: plain step.
constexpr double kLowestLogWeight = -700.0;

using Mat4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

// |t_k - s_k|^2 in the Fisher metric of t0's component k (whose covariance
// factor is `l`), for that component's differences (dm, dc, dl).
double fisher_term2(const Eigen::Matrix4d& l, const Eigen::Vector4d& dm, const Mat4& dc, double dl) {
  const Eigen::Vector4d y = l.triangularView<Eigen::Lower>().solve(dm);
  // L^-1 dS L^-T: its squared Frobenius norm is tr((S^-1 dS)^2).
  const Eigen::Matrix4d half = l.triangularView<Eigen::Lower>().solve(Eigen::Matrix4d(dc));
  const Eigen::Matrix4d whitened = l.triangularView<Eigen::Lower>().solve(half.transpose());
  return y.squaredNorm() + 0.5 * whitened.squaredNorm() + dl * dl;
}

}  // namespace

double squarem_step_length(const Working& t0, const Working& t1, const Working& t2, int threads) {
  const std::size_t m = t0.size();
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < m; ++k) {
    if (!(t0.log_weight[k] > kLowestLogWeight) || !(t1.log_weight[k] > kLowestLogWeight)) return 0.0;
    top = std::max(top, t0.log_weight[k]);
  }
  std::vector<double> weight(m);
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k) sum += weight[k] = std::exp(t0.log_weight[k] - top);
  // Each component's terms on the team (they are independent; this was
  // serial between the E-steps), then summed in component order, so the
  // length does not depend on the thread count.
  std::vector<double> r2_term(m), v2_term(m);
  std::vector<char> factored(m);
  parallel_for(m, threads, kComponentsPerClaim, [&](std::size_t k, int) {
    const Eigen::LLT<Eigen::Matrix4d> llt(Eigen::Map<const Mat4>(&t0.covariance[16 * k]));
    factored[k] = llt.info() == Eigen::Success ? 1 : 0;
    if (!factored[k]) return;
    const Eigen::Matrix4d l = llt.matrixL();
    const Eigen::Map<const Eigen::Vector4d> m0(&t0.mean[4 * k]), m1(&t1.mean[4 * k]), m2(&t2.mean[4 * k]);
    const Eigen::Map<const Mat4> c0(&t0.covariance[16 * k]), c1(&t1.covariance[16 * k]), c2(&t2.covariance[16 * k]);
    r2_term[k] = fisher_term2(l, m1 - m0, c1 - c0, t1.log_weight[k] - t0.log_weight[k]);
    v2_term[k] = fisher_term2(l, m2 - 2.0 * m1 + m0, c2 - 2.0 * c1 + c0,
                              t2.log_weight[k] - 2.0 * t1.log_weight[k] + t0.log_weight[k]);
  });
  for (std::size_t k = 0; k < m; ++k)
    if (!factored[k]) return 0.0;
  double r2 = 0.0, v2 = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const double w = weight[k] / sum;
    r2 += w * r2_term[k];
    v2 += w * v2_term[k];
  }
  const double a = std::sqrt(r2 / v2);
  return std::isfinite(a) ? a : 0.0;
}

Working squarem_extrapolate(const Working& t0, const Working& t1, const Working& t2, double a) {
  // t0 + 2a (t1 - t0) + a^2 (t2 - 2 t1 + t0), coefficient by coefficient.
  const double c0 = 1.0 - 2.0 * a + a * a, c1 = 2.0 * a - 2.0 * a * a, c2 = a * a;
  const auto mix = [&](const std::vector<double>& x0, const std::vector<double>& x1, const std::vector<double>& x2) {
    std::vector<double> out(x0.size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = c0 * x0[i] + c1 * x1[i] + c2 * x2[i];
    return out;
  };
  Working out{mix(t0.mean, t1.mean, t2.mean), mix(t0.covariance, t1.covariance, t2.covariance),
              mix(t0.log_weight, t1.log_weight, t2.log_weight)};
  // Weights through their logarithms (the softmax parameterisation): any
  // extrapolated log-weights are a distribution once renormalised.
  renormalise_log_weights(out.log_weight);
  return out;
}

void renormalise_log_weights(std::vector<double>& log_weight) {
  double top = -std::numeric_limits<double>::infinity();
  for (double l : log_weight) top = std::max(top, l);
  double sum = 0.0;
  for (double l : log_weight) sum += std::exp(l - top);
  const double log_sum = top + std::log(sum);
  for (double& l : log_weight) l -= log_sum;
}

void run_squarem(Working& w, const EmOptions& options, const EmPass& pass, const EmLoad& load,
                 const EmTolerance& tolerance, EmReport& report, const EmIterationCallback& on_iteration) {
  double previous = -std::numeric_limits<double>::infinity();
  int iter = 0;
  // A kept pass: reported, and the convergence test against the last kept one.
  const auto keep = [&](double ll) {
    report.iterations = iter;
    report.log_likelihood = ll;
    if (on_iteration) on_iteration(iter, ll);
    report.converged = std::fabs(ll - previous) < tolerance();
    previous = ll;
    return report.converged;
  };
  double step_max = kStepMax0;
  Working t0, t1, t2;
  while (iter < options.max_iter) {
    t0 = w;
    ++iter;
    if (keep(pass(w)) || iter == options.max_iter) break;
    t1 = w;
    ++iter;
    const double ll1 = pass(w);
    if (keep(ll1) || iter == options.max_iter) break;
    // w is t2 and current: a plain step needs nothing more.
    const double length = squarem_step_length(t0, t1, w, team_size(options.threads));
    const bool capped = length >= step_max;
    double a = std::min(length, step_max);
    if (!(a > kPlain)) {
      if (capped) step_max *= kStepFactor;  // the cap, not the step, made it plain
      continue;
    }
    Working next = squarem_extrapolate(t0, t1, w, a);
    if (!load(next, &w)) continue;  // no component extrapolated: t2 stays current
    t2.mean.swap(w.mean);
    t2.covariance.swap(w.covariance);
    t2.log_weight.swap(w.log_weight);
    w = std::move(next);
    ++iter;
    const double ll = pass(w);
    if (ll >= ll1) {
      ++report.extrapolations_kept;
      if (capped) step_max *= kStepFactor;
      if (keep(ll)) break;
    } else {
      // Rejected: back to t2, the plain step (always a model: an M-step's).
      ++report.extrapolations_rejected;
      if (capped) step_max = std::max(kStepMax0, step_max / kStepFactor);
      w = t2;
      load(w, nullptr);
      report.iterations = iter;
    }
  }
}

}  // namespace sogmm::detail
