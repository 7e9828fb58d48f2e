// The fit record of a saved model (Model::fit), written in one place for
// every front end: the C API's fits, the map's batches, the CLI and the
// benchmarks.
#pragma once

#include "sogmm/fit.hpp"
#include "sogmm/model.hpp"

namespace sogmm {

/// Fills model.fit from a fit and the options it ran with: the bandwidth (0
/// for a fixed K), the K asked for, tol, the floors the EM used
/// (record_reg_covar), max_iter, the EM's iterations, convergence and final
/// mean log-likelihood, and the kept run's seed, options.seed + result.run:
/// refitting with that seed and one run reproduces the model.
void record_fit(Model& model, const FitResult& result, const FitOptions& options);

}  // namespace sogmm
