// A sequence of small parallel loops, each followed by serial work, in ONE
// OpenMP region (private): e.g. k-means++'s steps (candidates' gains in
// parallel, then the chosen seed serially), thousands per fit.
//
// Why not one parallel_for per step: each region ends in a barrier that every
// team member must reach. On idle cores that costs microseconds; on a loaded
// machine a team member that the OS has descheduled holds the barrier for a
// scheduler slice, at every step: with other processes on both cores, the
// d = 5 seeding took 2.5 s in 627 regions instead of 0.03 s serially (issue
// 17). Here the calling thread never waits for a member that has not claimed
// work: items are claimed from a shared counter, so a descheduled member
// delays a stage only by the item it holds, and the region's one barrier
// comes at the end.
//
// Which to use: parallel_for (parallel.hpp) for a loop whose work per
// region is large against a region's cost (about a microsecond idle, a
// scheduler slice when loaded): the EM's waves, the queries, the mode
// count. parallel_stages for a sequence of many small loops with serial
// steps between them, where one region per loop would be paid thousands of
// times per fit: k-means++. Both count in the loop accounting
// (sogmm/loop_accounting.hpp) alike, one loop per parallel_for or stage.
#pragma once

#include <omp.h>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "parallel.hpp"

namespace sogmm::detail {

/// The waits of parallel_stages: spin, then yield, then sleep on a condition
/// variable. wake() after every change a waiter may wait for; it costs a
/// fence and a load unless a thread sleeps.
class StageWaiter {
 public:
  template <class Ready>
  void wait(const Ready& ready) {
    // About a stage's length of spinning and yielding first: most waits end
    // there, and a sleep would add a wake-up's latency to every stage.
    for (int spins = 0; spins < kSpins + kYields; ++spins) {
      if (ready()) return;
      if (spins > kSpins) std::this_thread::yield();
    }
    sleepers_.fetch_add(1, std::memory_order_seq_cst);
    std::atomic_thread_fence(std::memory_order_seq_cst);  // pairs with wake()'s fence
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wakeup_.wait(lock, ready);
    }
    sleepers_.fetch_sub(1, std::memory_order_relaxed);
  }
  /// Call after the store a waiter waits for: either the waiter's check
  /// after its increment sees the store, or this sees the increment and
  /// wakes it (the mutex closes the gap between its check and its sleep).
  void wake() {
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (sleepers_.load(std::memory_order_seq_cst) == 0) return;
    { const std::lock_guard<std::mutex> lock(mutex_); }
    wakeup_.notify_all();
  }

 private:
  static constexpr int kSpins = 2000;
  static constexpr int kYields = 200;
  std::atomic<int> sleepers_{0};
  std::mutex mutex_;
  std::condition_variable wakeup_;
};

/// For s = 0 .. stages - 1: calls item(s, i, thread) for every i in
/// [0, items(s)) on a team of `threads` threads, then between(s) on the
/// calling thread once every item of stage s has returned. items(s) is read
/// on the calling thread after between(s - 1), so a between may set up the
/// next stage. Which thread runs an item is unspecified: results must not
/// depend on it. The first exception (from an item or a between) stops the
/// stages and is rethrown on the calling thread.
template <class Items, class Item, class Between>
void parallel_stages(std::size_t stages, int threads, const Items& items, const Item& item, const Between& between) {
  // Each stage's items count as one loop of the loop accounting; the
  // betweens are serial work.
  if (threads <= 1 || stages == 0) {
    for (std::size_t s = 0; s < stages; ++s) {
      {
        const LoopTimer timer;
        for (std::size_t i = 0, n = items(s); i < n; ++i) item(s, i, 0);
      }
      between(s);
    }
    return;
  }
  // claim: stage in the high 32 bits, next unclaimed item in the low 32 (a
  // member late for stage s cannot claim an item of stage s + 1).
  std::atomic<std::uint64_t> claim{0};
  std::atomic<std::uint64_t> count{0};      // items of the open stage
  std::atomic<std::uint64_t> done{0};       // items of the open stage returned
  std::atomic<std::int64_t> open{-1};       // the stage whose items may be claimed
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  StageWaiter waiter;
  const auto fail = [&] {
    const std::lock_guard<std::mutex> lock(error_mutex);
    if (!first_error) first_error = std::current_exception();
    failed.store(true, std::memory_order_release);
    waiter.wake();
  };
  // Spins briefly, then yields the processor (a loaded machine needs it
  // more), then sleeps until woken: a wait longer than a stage (thread 0
  // calling a slow progress sink) costs no processor time.
  const auto wait_until = [&](const auto& ready) {
    waiter.wait([&] { return ready() || failed.load(std::memory_order_acquire); });
  };
  // Thread 0 opens stage s by storing claim, then count, then open (each
  // release); a member reads count before claim, so a count of a later
  // stage comes with that stage's claim tag and claims nothing here.
  // Team timing of each stage (loop accounting); written before `done`.
  TeamTimer team(threads);
  int members = threads;
  const auto run_items = [&](std::uint64_t s, int thread) {
    const std::uint64_t n = count.load(std::memory_order_acquire);
    std::uint64_t c = claim.load(std::memory_order_acquire);
    while (!failed.load(std::memory_order_relaxed)) {
      if ((c >> 32) != s || (c & 0xffffffffu) >= n) return;
      if (!claim.compare_exchange_weak(c, c + 1, std::memory_order_acq_rel, std::memory_order_acquire)) continue;
      const std::uint64_t t0 = team.on() ? wall_ns() : 0;
      try {
        if (thread == 0) progress_poll();
        item(static_cast<std::size_t>(s), static_cast<std::size_t>(c & 0xffffffffu), thread);
      } catch (...) {
        fail();
      }
      if (team.on()) team.item(thread, t0, wall_ns());
      done.fetch_add(1, std::memory_order_acq_rel);
      if (thread != 0) waiter.wake();  // thread 0 may be waiting for the stage's last item
      c = claim.load(std::memory_order_acquire);
    }
  };
#pragma omp parallel num_threads(threads)
  {
    const int thread = omp_get_thread_num();
    if (thread == 0) members = omp_get_num_threads();
    for (std::uint64_t s = 0; s < stages && !failed.load(std::memory_order_acquire); ++s) {
      if (thread == 0) {
        try {
          const std::uint64_t n = items(static_cast<std::size_t>(s));
          if (n > 0xffffffffu) throw std::length_error("parallel_stages: more than 2^32 - 1 items in a stage");
          done.store(0, std::memory_order_relaxed);
          team.reopen();
          claim.store(s << 32, std::memory_order_release);
          count.store(n, std::memory_order_release);
          open.store(static_cast<std::int64_t>(s), std::memory_order_release);
          waiter.wake();
          {
            const LoopTimer timer;
            run_items(s, 0);
            wait_until([&] { return done.load(std::memory_order_acquire) == n; });
          }
          team.close(members);
          if (!failed.load(std::memory_order_acquire)) between(static_cast<std::size_t>(s));
        } catch (...) {
          fail();
        }
      } else {
        wait_until([&] { return open.load(std::memory_order_acquire) >= static_cast<std::int64_t>(s); });
        // Thread 0 may have opened a later stage meanwhile; then the claim's
        // stage tag differs and this stage is skipped.
        if (open.load(std::memory_order_acquire) == static_cast<std::int64_t>(s)) run_items(s, thread);
      }
    }
  }
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace sogmm::detail
