// Report points of the progress mechanism (private; see sogmm/progress.hpp).
// Every function is a no-op costing one thread-local load when the calling
// thread has no ProgressScope, and must be called only from the thread that
// installed it (thread 0 of an OpenMP team is the thread that opened the
// region, so parallel loops call from thread 0). A cancelled sink makes them
// throw Error(ErrorCode::Cancelled); parallel_for then skips the indices not
// yet started on every thread.
#pragma once

#include <cstdint>

#include "sogmm/progress.hpp"

namespace sogmm::detail {

/// A stage starts at `step` of `total` (0 = unknown), with a log-likelihood
/// where it has one: always reported.
void progress_begin(Stage stage, std::uint64_t total, std::uint64_t step = 0, double log_likelihood = 0.0);
/// Step `step` of the current stage is done, with its log-likelihood: always
/// reported (EM iterations, runs).
void progress_event(std::uint64_t step, double log_likelihood);
/// Step `step` of the current stage is reached: reported when the last report
/// is kProgressIntervalMs old.
void progress_at(std::uint64_t step);
/// The same without a new step (a heartbeat inside a parallel loop).
void progress_poll();

}  // namespace sogmm::detail
