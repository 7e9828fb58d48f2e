#include "sogmm/fit_record.hpp"

#include "sogmm/reg_covar.hpp"

namespace sogmm {

void record_fit(Model& model, const FitResult& result, const FitOptions& options) {
  FitInfo& f = model.fit;
  f.known = true;
  f.bandwidth = options.n_components > 0 ? 0.0 : options.bandwidth;
  f.n_components_requested = options.n_components;
  f.tol = options.em.tol;
  // The limit the EM ran under: a warm start's pass cap stands in for
  // options.em.max_iter (WarmStartOptions::max_iter).
  f.max_iter = result.em.max_iter > 0 ? result.em.max_iter : options.em.max_iter;
  f.n_iter = result.em.iterations;
  f.converged = result.em.converged;
  f.log_likelihood = result.em.log_likelihood;
  f.seed = options.seed + static_cast<std::uint64_t>(result.run);  // wraps as the runs' seeds do
  record_reg_covar(model, result.em.reg_covar);
}

}  // namespace sogmm
