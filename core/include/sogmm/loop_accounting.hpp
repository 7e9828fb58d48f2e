// Thread-scaling diagnostics (issue 17): how much of the calling thread's CPU
// time the core's parallel loops take. Off by default; a benchmark turns it
// on, reads it around a stage run on one thread, and gets the stage's serial
// share f (Amdahl: two threads are at most 1 / (f + (1 - f) / 2) times
// faster). CPU time, unlike wall time, hardly moves when other processes load
// the machine.
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
};

/// Turns the accounting on or off for the whole process. When on, each
/// parallel loop reads the calling thread's CPU clock twice (about a
/// microsecond); when off, it costs one relaxed atomic load.
void set_loop_accounting(bool on);

/// The totals so far; subtract two readings to get one stage's.
LoopAccounting loop_accounting();

/// CPU seconds the calling thread has used (CLOCK_THREAD_CPUTIME_ID).
double thread_cpu_seconds();

}  // namespace sogmm
