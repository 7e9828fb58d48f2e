// sogmm_map_export_delta / sogmm_map_apply_delta: map deltas
// (sogmm/map_delta.hpp) as delta files in caller memory (spec/format.md 2.5).
#include <cstring>
#include <string>
#include <vector>

#include "internal.hpp"
#include "map_handle.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

extern "C" {

SOGMM_API sogmm_status sogmm_map_export_delta(const sogmm_map* map, uint64_t since_revision,
                                              const sogmm_options* options, void* out, size_t capacity,
                                              size_t* size) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_export_delta");
    sogmm_capi::require_nonnull(size, "size");
    if (out == nullptr && capacity != 0) sogmm_capi::fail(SOGMM_E_INVALID_ARG, "out is NULL with capacity > 0");
    const std::vector<std::uint8_t> bytes = sogmm::format::delta_to_bytes(
        map->map.delta_since(since_revision), sogmm_capi::opts_or_default(options).settings.write);
    *size = bytes.size();
    if (out == nullptr) return SOGMM_OK;  // the size query
    if (capacity < bytes.size())
      sogmm_capi::fail(SOGMM_E_BUFFER_TOO_SMALL, "the delta has " + std::to_string(bytes.size()) +
                                                     " bytes, out has room for " + std::to_string(capacity));
    std::memcpy(out, bytes.data(), bytes.size());
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_apply_delta(sogmm_map* map, const void* data, size_t size,
                                             const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    const sogmm_capi::MapWriter use(map, "sogmm_map_apply_delta");
    if (data == nullptr && size != 0) sogmm_capi::fail(SOGMM_E_INVALID_ARG, "data is NULL with size > 0");
    map->map.apply_delta(
        sogmm::format::delta_from_bytes(data, size, sogmm_capi::opts_or_default(options).settings.read));
  }
  SOGMM_CATCH
}

}  // extern "C"
