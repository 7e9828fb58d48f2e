// Progress reports and cancellation of long operations (fit, sampling, ...).
//
// One mechanism for every long call: a sink installed for the calling thread
// (ProgressScope) receives (stage, step, total, log-likelihood) reports and
// cancels the operation by returning true. The core reports only on the thread
// that installed the sink, never on a worker thread, so a sink may use
// thread-affine state (Python's signal handling, a thread-local error).
#pragma once

#include <cstdint>
#include <functional>

namespace sogmm {

/// What a long operation is doing. Values are stable: the C API's
/// SOGMM_STAGE_* constants have the same numbers.
enum class Stage : std::int32_t {
  ModeCount = 1,  ///< mean shift; step = seeds (flat) or iterations (blurring) done, total = their number
  Seeding = 2,    ///< k-means++; step = seeds chosen, total = K
  Em = 3,         ///< EM; step = iterations done (0 at the start), total = max_iter, log-likelihood of the last
  Run = 4,        ///< n_init > 1 only: run `step` (from 1) starts, total = n_init, best log-likelihood so far
  Sampling = 5,   ///< sampling; step = points drawn, total = points requested
  Scoring = 6,    ///< log-likelihood of points (map queries); step = points scored, total = points
  Regression = 7, ///< gray regression (map queries); step = points done, total = points
  Rendering = 8,  ///< rendering an image (sogmm/render.hpp); step = rows done, total = image height
  Registration = 9,  ///< registration (sogmm/registration.hpp); step = iterations done, total = levels x max_iter, mean LL
};

/// One report. `total` is 0 when unknown; `log_likelihood` is the mean
/// log-likelihood per point where the stage has one (EM, Run), else 0.
struct Progress {
  Stage stage = Stage::ModeCount;
  std::uint64_t step = 0;
  std::uint64_t total = 0;
  double log_likelihood = 0.0;
};

/// Receives reports; returning true cancels: the operation throws
/// Error(ErrorCode::Cancelled) within one report interval, after freeing
/// everything and without writing any output. Reports come at the start of
/// each stage, after each EM iteration and, during long loops, once
/// kProgressIntervalMs have passed since the sink last returned (plus one
/// work chunk: a few milliseconds), so a slow sink slows the operation by its
/// own time only. Within a stage, steps never decrease. While the sink runs
/// its thread has no sink: a SOGMM call it makes starts without one (a
/// nested fit reports nothing). A sink that throws cancels with its own
/// exception.
using ProgressSink = std::function<bool(const Progress&)>;

/// Heartbeat period of long loops, in milliseconds of work between the
/// sink's return and its next call. The clock only decides when the sink is
/// called: results never depend on it.
inline constexpr int kProgressIntervalMs = 20;

/// Installs `sink` for the SOGMM calls the constructing thread makes while
/// the scope lives; scopes nest (the innermost wins; an empty sink installs
/// nothing). Not copyable; destroy on the constructing thread.
class ProgressScope {
 public:
  explicit ProgressScope(ProgressSink sink);
  ~ProgressScope();
  ProgressScope(const ProgressScope&) = delete;
  ProgressScope& operator=(const ProgressScope&) = delete;

  struct State;  ///< private: the report state of one scope

 private:
  State* state_;
  State* previous_;
};

}  // namespace sogmm
