// Thread-scaling diagnostics (issue 17), for benchmarks only (not part of the
// C API): how much of the calling thread's CPU time the core's parallel loops
// take, and where a team's wall time inside them goes. Off by default; a
// benchmark turns it on and reads it around a stage.
// - On one thread it gives the stage's serial share f (Amdahl: two threads
//   are at most 1 / (f + (1 - f) / 2) times faster). CPU time, unlike wall
//   time, hardly moves when other processes load the machine.
// - On a team it splits each loop's wall time into the members' mean busy
//   time and three losses (start, imbalance, join), so that a speed-up below
//   Amdahl's bound can be traced to its cause. These are wall times: measure
//   them on idle cores.
#pragma once

#include <cstdint>

namespace sogmm {

/// Totals since the process started (counted only while accounting is on).
struct LoopAccounting {
  /// Parallel loops run (each opens one OpenMP region on more than one thread).
  std::uint64_t loops = 0;
  /// CPU seconds the thread that started each loop spent inside it: on one
  /// thread, all the loop's work; on more, its share plus its waiting.
  double cpu_seconds_in_loops = 0.0;

  /// Loops run by a team of more than one thread, and their wall time split
  /// as wall = busy + start + imbalance + join (seconds, summed over loops).
  /// Per loop, with times measured from when the calling thread opens it and
  /// s_k, e_k the times member k starts and finishes its share:
  ///  - busy: the members' mean time in the loop, mean(e_k - s_k) (the work
  ///    per thread if it were spread evenly; compare twice it with the same
  ///    loops' one-thread time to see work inflation, e.g. shared caches);
  ///  - start: mean(s_k), waking the team;
  ///  - imbalance: max(e_k) - mean(e_k), the last member's lateness;
  ///  - join: wall - max(e_k), the barrier and returning to the caller.
  /// In a staged region (several loops in one region, parallel_stages.hpp)
  /// each stage is one loop, a member's busy time is the sum of its items,
  /// e_k the end of its last item (0 if it took none) and s_k = e_k - busy.
  std::uint64_t team_loops = 0;
  double team_wall_seconds = 0.0;
  double team_busy_seconds = 0.0;
  double team_start_seconds = 0.0;
  double team_imbalance_seconds = 0.0;
  double team_join_seconds = 0.0;
};

/// Turns the accounting on or off for the whole process. When on, each
/// parallel loop reads the calling thread's CPU clock twice (about a
/// microsecond) and each team member the monotonic clock twice (per item in a
/// staged region); when off, it costs one relaxed atomic load.
void set_loop_accounting(bool on);

/// The totals so far; subtract two readings to get one stage's.
LoopAccounting loop_accounting();

/// CPU seconds the calling thread has used (CLOCK_THREAD_CPUTIME_ID).
double thread_cpu_seconds();

}  // namespace sogmm
