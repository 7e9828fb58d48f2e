// OpenMP in the core (private): how many threads a parallel loop may start,
// and a parallel loop that carries exceptions out of the parallel region.
//
// Why: an exception that leaves an OpenMP structured block calls
// std::terminate, so a std::bad_alloc in one worker used to abort the whole
// process instead of becoming an out-of-memory error; and libgomp ends the
// process when it cannot create a thread, so a large thread request under a
// memory limit (each thread needs a stack) did the same.
#pragma once

#include <omp.h>

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>

#include "progress.hpp"

namespace sogmm::detail {

/// Threads per processor above which no team grows (see team_size).
inline constexpr int kThreadsPerProcessor = 4;

/// The number of threads the core starts for a request of `requested`
/// threads (0 = OpenMP's default, omp_get_max_threads(), e.g. from
/// OMP_NUM_THREADS): the request clamped to [1, kThreadsPerProcessor x
/// omp_get_num_procs()]. More threads than processors cannot speed up these
/// compute-bound loops, and each one costs a stack (the RLIMIT_STACK size,
/// 8 MiB by default); results never depend on the team size.
inline int team_size(int requested) {
  const int cap = kThreadsPerProcessor * std::max(1, omp_get_num_procs());
  const int wanted = requested > 0 ? requested : omp_get_max_threads();
  return std::clamp(wanted, 1, cap);
}

/// CPU nanoseconds the calling thread has used.
inline std::uint64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000u + static_cast<std::uint64_t>(ts.tv_nsec);
}

/// The loop accounting of sogmm/loop_accounting.hpp (process-wide).
struct LoopTally {
  std::atomic<bool> on{false};
  std::atomic<std::uint64_t> loops{0};
  std::atomic<std::uint64_t> cpu_ns{0};
};
inline LoopTally loop_tally;

/// Adds one loop and the calling thread's CPU time from construction to
/// destruction (however the loop ends) when the accounting is on.
class LoopTimer {
 public:
  LoopTimer() : on_(loop_tally.on.load(std::memory_order_relaxed)), start_(on_ ? thread_cpu_ns() : 0) {}
  ~LoopTimer() {
    if (!on_) return;
    loop_tally.loops.fetch_add(1, std::memory_order_relaxed);
    loop_tally.cpu_ns.fetch_add(thread_cpu_ns() - start_, std::memory_order_relaxed);
  }
  LoopTimer(const LoopTimer&) = delete;
  LoopTimer& operator=(const LoopTimer&) = delete;

 private:
  bool on_;
  std::uint64_t start_;
};

/// Calls body(i, thread) for every i in [0, n) on a team of `threads`
/// threads, handing out `chunk` consecutive indices at a time (OpenMP
/// schedule(dynamic, chunk)); `thread` is the caller's omp_get_thread_num(),
/// below `threads`, for indexing per-thread scratch allocated beforehand. If
/// a call throws, the calls not yet started are skipped and the first
/// exception is rethrown on the calling thread once the team has finished.
/// Thread 0 (the calling thread) polls the progress sink at the start of each
/// chunk it takes, so a cancel (a throw there) stops every thread within one
/// chunk.
template <class Body>
void parallel_for(std::size_t n, int threads, std::size_t chunk, const Body& body) {
  const LoopTimer timer;
  // One thread: a plain loop (same order as a one-thread team), without the
  // cost of opening a parallel region, e.g. once per k-means++ step.
  if (threads <= 1) {
    for (std::size_t i = 0; i < n; ++i) {
      if (i % std::max<std::size_t>(chunk, 1) == 0) progress_poll();
      body(i, 0);
    }
    return;
  }
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const std::size_t step = std::max<std::size_t>(chunk, 1);
#pragma omp parallel for num_threads(threads) schedule(dynamic, step)
  for (std::size_t i = 0; i < n; ++i) {
    if (failed.load(std::memory_order_relaxed)) continue;
    try {
      const int thread = omp_get_thread_num();
      if (thread == 0 && i % step == 0) progress_poll();
      body(i, thread);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error) first_error = std::current_exception();
      failed.store(true, std::memory_order_relaxed);
    }
  }
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace sogmm::detail
