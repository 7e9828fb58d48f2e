// SQUAREM-accelerated EM (EmAcceleration::Squarem; private to em.cpp).
//
// Varadhan & Roland (2008), "Simple and globally convergent methods for
// accelerating the convergence of any EM algorithm", scheme S3: from a model
// t0 and two EM steps t1 = F(t0), t2 = F(t1), with r = t1 - t0 and
// v = t2 - 2 t1 + t0, the extrapolated model is t0 + 2 a r + a^2 v with
// a = |r| / |v| (a = 1 gives t2 exactly), followed by one EM step from it.
#pragma once

#include <functional>

#include "em_working.hpp"
#include "sogmm/em.hpp"

namespace sogmm::detail {

/// One E+M pass: evaluates the model last made current (returns its mean
/// log-likelihood per point) and writes the M-step's model into `w`, which
/// becomes current.
using EmPass = std::function<double(Working& w)>;
/// Makes `w` the current model. With `fallback` (an extrapolation, and the
/// M-step's model it extrapolates from): every component of `w` that is not
/// a component (a covariance not positive definite, a non-finite constant)
/// or lies outside the set the M-step maps into (a covariance minus the
/// reg_covar diagonal not positive definite: from there the next M-step,
/// which adds the floors back, could lower the likelihood) is replaced by
/// `fallback`'s and the log-weights renormalised; it returns false (and
/// `fallback` stays current) when every component was replaced. Without:
/// returns false and changes nothing when `w` is not a model.
using EmLoad = std::function<bool(Working& w, const Working* fallback)>;

/// The convergence tolerance after the last pass (em.cpp: tol, or the last
/// E-step's standard error times EmOptions::tol_standard_errors when larger).
using EmTolerance = std::function<double()>;

/// Runs EM from the current model `w` with SQUAREM steps until
/// |change of the log-likelihood| < tolerance() or options.max_iter passes.
/// Safeguards: a component whose extrapolation is not one, or leaves its
/// reg_covar floors, takes the plain step (t2's) while the others
/// extrapolate (a component of fewer points than dimensions sits on its
/// floor and would otherwise stop every extrapolation of the model), and an
/// extrapolated model whose log-likelihood is below t1's is rejected (the run
/// continues from t2, as plain EM would). The model returned in `w` is always an M-step's (its
/// floors and the depth floor hold). The EM step after a kept extrapolation
/// may lower the likelihood slightly (the M-step's reg_covar floors: see
/// EmOptions::acceleration). `on_iteration`
/// sees every pass but the rejected ones (its numbers then skip one);
/// report->iterations counts every pass.
void run_squarem(Working& w, const EmOptions& options, const EmPass& pass, const EmLoad& load,
                 const EmTolerance& tolerance, EmReport& report, const EmIterationCallback& on_iteration);

/// The extrapolated model t0 + 2 a r + a^2 v (log-weights renormalised).
/// Exposed for its test.
Working squarem_extrapolate(const Working& t0, const Working& t1, const Working& t2, double a);

/// Subtracts log(sum exp(l)) from every l, so the weights sum to 1.
void renormalise_log_weights(std::vector<double>& log_weight);

/// |r| / |v| in the Fisher metric of t0 (sum over components of
/// w_k (dmu^T S^-1 dmu + tr((S^-1 dS)^2) / 2 + dlogw^2), w_k, S = t0's weight
/// and covariance), so the step length does not depend on the data's units
/// or offset; 0 when it cannot be measured (t0 not a model, a weight below
/// e^-700, v = 0). The components' terms are computed on `threads` threads
/// and summed in component order: the same length for any thread count.
double squarem_step_length(const Working& t0, const Working& t1, const Working& t2, int threads);

}  // namespace sogmm::detail
