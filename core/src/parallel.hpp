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
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <vector>

#include "progress.hpp"

namespace sogmm::detail {

/// Sets the OpenMP thread count of the calling thread for its lifetime and
/// restores the caller's setting afterwards, even on error (fit(), the warm
/// start and the map's mode-count check run their parallel loops under one).
class ScopedOmpThreads {
 public:
  explicit ScopedOmpThreads(int n) : saved_(omp_get_max_threads()) { omp_set_num_threads(n); }
  ~ScopedOmpThreads() { omp_set_num_threads(saved_); }
  ScopedOmpThreads(const ScopedOmpThreads&) = delete;
  ScopedOmpThreads& operator=(const ScopedOmpThreads&) = delete;

 private:
  int saved_;
};

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

/// Monotonic nanoseconds (a vDSO call, tens of nanoseconds).
inline std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
}

/// The loop accounting of sogmm/loop_accounting.hpp (process-wide).
struct LoopTally {
  std::atomic<bool> on{false};
  std::atomic<std::uint64_t> loops{0};
  std::atomic<std::uint64_t> cpu_ns{0};
  std::atomic<std::uint64_t> team_loops{0};
  std::atomic<std::int64_t> team_wall_ns{0}, team_busy_ns{0}, team_start_ns{0}, team_imbalance_ns{0}, team_join_ns{0};
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

/// One team loop's member timings for the loop accounting (a no-op when it is
/// off): member k writes only its own slot, and the calling thread adds the
/// loop to the tally (LoopAccounting::team_*) once every member is done.
class TeamTimer {
 public:
  explicit TeamTimer(int threads) : on_(loop_tally.on.load(std::memory_order_relaxed)) {
    if (on_) slots_.resize(static_cast<std::size_t>(std::max(threads, 1)));
    reopen();
  }
  bool on() const { return on_; }
  /// A new loop starts now (a staged region's next stage): slots cleared.
  void reopen() {
    if (!on_) return;
    for (Slot& slot : slots_) slot = Slot{};
    open_ = wall_ns();
  }
  /// parallel_for: member k starts, then finishes, its share.
  void arrive(int k) {
    if (on_) slots_[static_cast<std::size_t>(k)].start = wall_ns();
  }
  void leave(int k) {
    if (!on_) return;
    Slot& slot = slots_[static_cast<std::size_t>(k)];
    slot.end = wall_ns();
    slot.busy = slot.end - slot.start;
  }
  /// Staged region: member k ran one item from t0 to t1 (wall_ns()).
  void item(int k, std::uint64_t t0, std::uint64_t t1) {
    Slot& slot = slots_[static_cast<std::size_t>(k)];
    slot.busy += t1 - t0;
    slot.end = t1;
  }
  /// Adds the loop (its first `members` slots) to the tally; call after
  /// every member's last write is visible (after the region, or after the
  /// stage's completion count was read with acquire).
  void close(int members) {
    if (!on_) return;
    const std::int64_t wall = static_cast<std::int64_t>(wall_ns() - open_);
    const std::size_t count = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(members, 1)), 1, slots_.size());
    double busy = 0.0, start = 0.0, end = 0.0, last = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      // e_k from the opening (0 for a member that took no item), s_k = e_k - busy_k.
      const double e = slots_[k].end > open_ ? static_cast<double>(slots_[k].end - open_) : 0.0;
      const double b = static_cast<double>(slots_[k].busy);
      busy += b, start += e - b, end += e, last = std::max(last, e);
    }
    const double n = static_cast<double>(count);
    loop_tally.team_loops.fetch_add(1, std::memory_order_relaxed);
    loop_tally.team_wall_ns.fetch_add(wall, std::memory_order_relaxed);
    loop_tally.team_busy_ns.fetch_add(static_cast<std::int64_t>(busy / n), std::memory_order_relaxed);
    loop_tally.team_start_ns.fetch_add(static_cast<std::int64_t>(start / n), std::memory_order_relaxed);
    loop_tally.team_imbalance_ns.fetch_add(static_cast<std::int64_t>(last - end / n), std::memory_order_relaxed);
    loop_tally.team_join_ns.fetch_add(wall - static_cast<std::int64_t>(last), std::memory_order_relaxed);
  }

 private:
  // One cache line per member, so that timing does not add false sharing.
  struct alignas(64) Slot {
    std::uint64_t start = 0, end = 0, busy = 0;
  };
  bool on_;
  std::uint64_t open_ = 0;
  std::vector<Slot> slots_;
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
  // One thread, or one claim's worth of work (which one member would take
  // whole): a plain loop (same order as a one-thread team), without the
  // cost of opening a parallel region, e.g. once per k-means++ step, or a
  // small fit's set-up loops.
  if (threads <= 1 || n <= std::max<std::size_t>(chunk, 1)) {
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
  TeamTimer team(threads);
  int members = threads;
  // The loop's own barrier is dropped (nowait) so that each member's finish
  // can be timed; the region's barrier takes its place.
#pragma omp parallel num_threads(threads)
  {
    const int thread = omp_get_thread_num();
    if (thread == 0) members = omp_get_num_threads();
    team.arrive(thread);
#pragma omp for schedule(dynamic, step) nowait
    for (std::size_t i = 0; i < n; ++i) {
      if (failed.load(std::memory_order_relaxed)) continue;
      try {
        if (thread == 0 && i % step == 0) progress_poll();
        body(i, thread);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        failed.store(true, std::memory_order_relaxed);
      }
    }
    team.leave(thread);
  }
  team.close(members);
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace sogmm::detail
