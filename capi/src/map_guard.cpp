// The map handle's use guard (map_handle.hpp): a map is shared by const calls
// or held by one non-const call; a call that finds it otherwise fails at once
// with SOGMM_E_BUSY. Why not a lock: the other user may be this very thread
// (a progress callback calling into the map whose insert is running it), and
// waiting would deadlock; a clear error is the documented rule (sogmm.h).
#include <string>

#include "map_handle.hpp"

namespace sogmm_capi {
namespace {

// `conflict` says what the other call is doing.
[[noreturn]] void busy(const char* call, const char* conflict) {
  fail(SOGMM_E_BUSY, std::string("map busy: ") + call + " cannot run while " + conflict +
                         " (on another thread, or the call whose progress callback is running); "
                         "a map is changed by one call at a time");
}

// Marks the map held by one changing call if no call uses it.
bool take_alone(sogmm_map* map) noexcept {
  std::int64_t idle = 0;
  return map->users.compare_exchange_strong(idle, -1, std::memory_order_acquire, std::memory_order_relaxed);
}

}  // namespace

MapWriter::MapWriter(sogmm_map* map, const char* call) : map_(map) {
  if (!take_alone(map_)) busy(call, "another call is using the map");
}

MapWriter::~MapWriter() { map_->users.store(0, std::memory_order_release); }

bool take_for_free(sogmm_map* map) noexcept {
  if (take_alone(map)) return true;
  set_error(SOGMM_E_BUSY,
            "map busy: sogmm_map_free did not free the map, which another call is using (on another thread, or "
            "the call whose progress callback is running); free it once no call uses it");
  return false;
}

MapReader::MapReader(const sogmm_map* map, const char* call) : map_(map) {
  std::int64_t n = map_->users.load(std::memory_order_relaxed);
  do {
    if (n < 0) busy(call, "a call changing the map runs");
  } while (!map_->users.compare_exchange_weak(n, n + 1, std::memory_order_acquire, std::memory_order_relaxed));
}

MapReader::~MapReader() { map_->users.fetch_sub(1, std::memory_order_release); }

}  // namespace sogmm_capi
