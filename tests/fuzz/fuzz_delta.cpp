// Fuzz target: map deltas (spec/format.md 2.5) from bytes in memory,
// decoded and applied to a new map. Invariants: a delta the reader accepts
// re-encodes and reads back with the same steps and digest; applying it
// either succeeds with the delta's revision or throws and leaves the map at
// revision 0 with no component.
#include <cstdint>

#include "fuzz_util.hpp"
#include "sogmm/error.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sogmm::format::ReadOptions o;
  o.max_decoded_bytes = 4 << 20;
  sogmm::MapDelta d;
  try {
    d = sogmm::format::delta_from_bytes(data, size, o);
  } catch (const sogmm::Error&) {
    return 0;
  }
  const std::vector<std::uint8_t> again = sogmm::format::delta_to_bytes(d);
  const sogmm::MapDelta back = sogmm::format::delta_from_bytes(again.data(), again.size(), o);
  FUZZ_CHECK(back.digest == d.digest && back.ops.size() == d.ops.size() && back.revision == d.revision);
  sogmm::Map map;
  try {
    map.apply_delta(d);
    FUZZ_CHECK(map.revision() == d.revision);
  } catch (const sogmm::Error&) {
    FUZZ_CHECK(map.revision() == 0 && map.size() == 0 && map.frames().empty());
  }
  return 0;
}
