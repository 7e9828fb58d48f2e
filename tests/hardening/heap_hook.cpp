// Replaces the global operator new / delete of the hardening test executable
// (see heap_hook.hpp). Blocks come from std::malloc with a 64-byte header that
// records their size, so that AddressSanitizer still tracks them (its leak
// checker then reports anything a failing call forgets to free).
#include "heap_hook.hpp"

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {

std::atomic<long long> g_live_bytes{0}, g_live_blocks{0}, g_peak{0};
std::atomic<long long> g_countdown{0};  // > 0: allocations left before the injected failure
std::atomic<bool> g_armed{false}, g_fired{false};

// Room for the size in front of every block, keeping alignments up to 64.
constexpr std::size_t kHeader = 64;

bool inject_failure() {
  if (!g_armed.load(std::memory_order_relaxed)) return false;
  if (g_countdown.fetch_sub(1) != 1) return false;
  g_fired.store(true);
  return true;
}

// nullptr on (real or injected) failure.
void* try_allocate(std::size_t n, std::size_t alignment) {
  const std::size_t header = alignment > kHeader ? alignment : kHeader;
  if (inject_failure() || n > static_cast<std::size_t>(-1) - header) return nullptr;
  void* raw = nullptr;
  if (::posix_memalign(&raw, header, n + header) != 0) return nullptr;
  char* p = static_cast<char*>(raw) + header;
  reinterpret_cast<std::size_t*>(p)[-1] = n;
  reinterpret_cast<std::size_t*>(p)[-2] = header;
  const long long live = g_live_bytes.fetch_add(static_cast<long long>(n)) + static_cast<long long>(n);
  g_live_blocks.fetch_add(1);
  long long peak = g_peak.load();
  while (live > peak && !g_peak.compare_exchange_weak(peak, live)) {
  }
  return p;
}

void* allocate(std::size_t n, std::size_t alignment) {
  void* p = try_allocate(n, alignment);
  if (!p) throw std::bad_alloc();
  return p;
}

void release(void* q) noexcept {
  if (!q) return;
  char* p = static_cast<char*>(q);
  const std::size_t n = reinterpret_cast<std::size_t*>(p)[-1];
  const std::size_t header = reinterpret_cast<std::size_t*>(p)[-2];
  g_live_bytes.fetch_sub(static_cast<long long>(n));
  g_live_blocks.fetch_sub(1);
  std::free(p - header);
}

}  // namespace

namespace sogmm::test::heap {
long long live_bytes() { return g_live_bytes.load(); }
long long live_blocks() { return g_live_blocks.load(); }
long long peak_bytes() { return g_peak.load(); }
void reset_peak() { g_peak.store(g_live_bytes.load()); }
void fail_nth_allocation(long long n) {
  g_fired.store(false);
  g_countdown.store(n);
  g_armed.store(true);
}
bool stop_failing() {
  g_armed.store(false);
  return g_fired.load();
}
}  // namespace sogmm::test::heap

constexpr std::size_t kDefaultAlignment = __STDCPP_DEFAULT_NEW_ALIGNMENT__;

void* operator new(std::size_t n) { return allocate(n, kDefaultAlignment); }
void* operator new[](std::size_t n) { return allocate(n, kDefaultAlignment); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return try_allocate(n, kDefaultAlignment); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return try_allocate(n, kDefaultAlignment); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return try_allocate(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return try_allocate(n, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete(void* p, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
