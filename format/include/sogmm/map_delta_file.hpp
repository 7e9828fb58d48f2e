// Map deltas in the .sogmm container (spec/format.md section 2.5): a delta
// is a model container whose features_required has bit 0 (map_delta) set, so
// that a model reader refuses it (unsupported_feature) and only a delta
// reader takes it. Written as format 1.2, its key/values packed and
// compressed in the body (bit 1, section 2.5.1); deltas of format 1.1 (key/
// values in the metadata) still read. Errors as sogmm/format.hpp, plus the
// delta keys' (Error(Format), sogmm::delta_from_model).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/file_options.hpp"
#include "sogmm/map_delta.hpp"

namespace sogmm::format {

/// The metadata key of a delta of format 1.2 that locates its key/values,
/// packed in the body (spec/format.md section 2.5.1, features_required bit 1).
inline constexpr const char* kPackedKeyValuesKey = "packed_key_values";

/// The bytes of a delta file. Refuses (throws, nothing written) what a delta
/// reader would reject.
std::vector<std::uint8_t> delta_to_bytes(const MapDelta& delta, const WriteOptions& options = {});

/// Reads and fully verifies a delta file: the reading procedure of section 9
/// with the delta rules of section 2.5 (M may be 0; the weights need not
/// sum to 1; covariances returned as stored), then the delta keys. A model
/// file -> FormatError "not_a_delta".
MapDelta delta_from_bytes(const void* data, std::size_t size, const ReadOptions& options = {});

/// delta_to_bytes() written atomically (as save()).
void save_delta(const std::string& path, const MapDelta& delta, const WriteOptions& options = {});

/// delta_from_bytes() of a file (read piecewise, as load()).
MapDelta load_delta(const std::string& path, const ReadOptions& options = {});

}  // namespace sogmm::format
