// Thread-scaling diagnostics (sogmm/loop_accounting.hpp); the counters live
// in parallel.hpp, next to the loop that feeds them.
#include "sogmm/loop_accounting.hpp"

#include "parallel.hpp"

namespace sogmm {

void set_loop_accounting(bool on) { detail::loop_tally.on.store(on, std::memory_order_relaxed); }

LoopAccounting loop_accounting() {
  LoopAccounting a;
  a.loops = detail::loop_tally.loops.load(std::memory_order_relaxed);
  a.cpu_seconds_in_loops = 1e-9 * static_cast<double>(detail::loop_tally.cpu_ns.load(std::memory_order_relaxed));
  const detail::LoopTally& t = detail::loop_tally;
  const auto seconds = [](const std::atomic<std::int64_t>& ns) {
    return 1e-9 * static_cast<double>(ns.load(std::memory_order_relaxed));
  };
  a.team_loops = t.team_loops.load(std::memory_order_relaxed);
  a.team_wall_seconds = seconds(t.team_wall_ns);
  a.team_busy_seconds = seconds(t.team_busy_ns);
  a.team_start_seconds = seconds(t.team_start_ns);
  a.team_imbalance_seconds = seconds(t.team_imbalance_ns);
  a.team_join_seconds = seconds(t.team_join_ns);
  return a;
}

double thread_cpu_seconds() { return 1e-9 * static_cast<double>(detail::thread_cpu_ns()); }

}  // namespace sogmm
