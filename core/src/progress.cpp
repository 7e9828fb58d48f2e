// The thread-local progress sink and its throttled reports.
#include "progress.hpp"

#include <chrono>
#include <string>
#include <utility>

#include "sogmm/error.hpp"

namespace sogmm {

struct ProgressScope::State {
  ProgressSink sink;
  Progress current;
  std::chrono::steady_clock::time_point last_report;
  bool cancelled = false;
};

namespace {

thread_local ProgressScope::State* t_state = nullptr;

const char* stage_name(Stage stage) {
  switch (stage) {
    case Stage::ModeCount: return "the mode count";
    case Stage::Seeding: return "seeding";
    case Stage::Em: return "EM";
    case Stage::Run: return "run";
    case Stage::Sampling: return "sampling";
    case Stage::Scoring: return "scoring";
    case Stage::Regression: return "gray regression";
    case Stage::Rendering: return "rendering";
    case Stage::Registration: return "registration";
  }
  return "an unknown stage";
}

[[noreturn]] void throw_cancelled(const Progress& p) {
  std::string where = stage_name(p.stage);
  if (p.stage == Stage::Em) where += " iteration " + std::to_string(p.step);
  if (p.stage == Stage::Run) where += " " + std::to_string(p.step);
  throw Error(ErrorCode::Cancelled, "cancelled by the progress callback during " + where);
}

// While the sink runs, the calling thread has no sink: a SOGMM call made
// inside it starts without one, instead of reporting to the sink that is
// running (which could call it again, without bound).
class SinkRunning {
 public:
  SinkRunning() : saved_(t_state) { t_state = nullptr; }
  ~SinkRunning() { t_state = saved_; }
  SinkRunning(const SinkRunning&) = delete;
  SinkRunning& operator=(const SinkRunning&) = delete;

 private:
  ProgressScope::State* saved_;
};

// Calls the sink with the current report; a true return cancels for good
// (every later report point throws too). The interval to the next heartbeat
// is timed from the sink's return, so a slow sink adds its own time once per
// report, and the work between two heartbeats is kProgressIntervalMs
// whatever the sink costs.
void report(ProgressScope::State& s) {
  if (!s.cancelled) {
    {
      const SinkRunning running;
      s.cancelled = s.sink(s.current);
    }
    s.last_report = std::chrono::steady_clock::now();
  }
  if (s.cancelled) throw_cancelled(s.current);
}

bool due(const ProgressScope::State& s) {
  return std::chrono::steady_clock::now() - s.last_report >= std::chrono::milliseconds(kProgressIntervalMs);
}

}  // namespace

ProgressScope::ProgressScope(ProgressSink sink) : state_(nullptr), previous_(t_state) {
  if (!sink) return;
  state_ = new State{std::move(sink), {}, std::chrono::steady_clock::now(), false};
  t_state = state_;
}

ProgressScope::~ProgressScope() {
  if (!state_) return;
  t_state = previous_;
  delete state_;
}

namespace detail {

void progress_begin(Stage stage, std::uint64_t total, std::uint64_t step, double log_likelihood) {
  if (!t_state) return;
  t_state->current = Progress{stage, step, total, log_likelihood};
  report(*t_state);
}

void progress_event(std::uint64_t step, double log_likelihood) {
  if (!t_state) return;
  t_state->current.step = step;
  t_state->current.log_likelihood = log_likelihood;
  report(*t_state);
}

void progress_at(std::uint64_t step) {
  if (!t_state) return;
  if (step > t_state->current.step) t_state->current.step = step;
  if (t_state->cancelled || due(*t_state)) report(*t_state);
}

void progress_poll() {
  if (t_state && (t_state->cancelled || due(*t_state))) report(*t_state);
}

}  // namespace detail
}  // namespace sogmm
