// The sogmm_map handle, shared by map.cpp (create, insert, flush, files) and
// map_queries.cpp (score, regress, sample), and its use guard (map_guard.cpp).
// Never installed.
#pragma once

#include <atomic>
#include <cstdint>

#include "internal.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_tracking.hpp"

struct sogmm_map {
  sogmm::Map map;
  sogmm_options options;  ///< the creation options: RGB-D keys and progress callback of later inserts
  /// sogmm_map_track_frame's last inserted frame (its odometry target).
  sogmm::TrackingState tracking;
  /// Calls using the map: n > 0 const calls, or -1 for the one non-const
  /// call (or sogmm_map_free). A call that cannot take it returns
  /// SOGMM_E_BUSY instead of racing (sogmm.h, "map busy"). Mutable: the
  /// guard's own state, which const calls take too.
  mutable std::atomic<std::int64_t> users{0};
};

namespace sogmm_capi {

/// Exclusive use of `map` for one non-const call named `call`, released on
/// destruction; throws SOGMM_E_BUSY ("map busy: ...") when any other call is
/// using the map: another thread's, or the call whose progress callback this
/// is. Never waits.
class MapWriter {
 public:
  MapWriter(sogmm_map* map, const char* call);
  ~MapWriter();
  MapWriter(const MapWriter&) = delete;
  MapWriter& operator=(const MapWriter&) = delete;

 private:
  sogmm_map* map_;
};

/// Shared use of `map` for one const call: any number of them at once;
/// throws SOGMM_E_BUSY while a non-const call is using the map.
class MapReader {
 public:
  MapReader(const sogmm_map* map, const char* call);
  ~MapReader();
  MapReader(const MapReader&) = delete;
  MapReader& operator=(const MapReader&) = delete;

 private:
  const sogmm_map* map_;
};

/// sogmm_map_free's take: true when no call is using `map` (which then
/// belongs to the caller, to delete); false, with the thread's last error set
/// to "map busy: ...", when one is (the map must not be freed).
bool take_for_free(sogmm_map* map) noexcept;

}  // namespace sogmm_capi
