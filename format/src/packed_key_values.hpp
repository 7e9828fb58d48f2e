// Packed key/values (spec/format.md section 2.5.1, feature bit 1): a map
// delta's key/value entries stored in the body, compressed with zstd, instead
// of as metadata strings. The frame provenance and step lines of a delta are
// text of a few KB that zstd shrinks about 3x; in the metadata they are stored
// raw (a FlatBuffer string is never compressed).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "container.hpp"
#include "source.hpp"
#include "sogmm/file_options.hpp"
#include "sogmm/map_delta_file.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format::detail {

/// features_required bit 1: the file's key/values are (also) packed in the body.
inline constexpr std::uint64_t kFeaturePackedKeyValues = 2;

using sogmm::format::kPackedKeyValuesKey;

/// The packed form of a list of entries: the stored bytes (placed last in the
/// body, right before the end marker) and the metadata entry that describes
/// them ("codec stored_length decoded_length crc32c", decimal).
struct PackedKeyValues {
  std::vector<std::uint8_t> stored;
  std::pair<std::string, std::string> entry;
};

/// Packs `entries` (each key and value: UTF-8 without NUL, checked by the
/// caller): key NUL value NUL, one entry after another, then zstd at
/// options.zstd_level when options.compress and that is smaller, else raw.
PackedKeyValues pack_key_values(const std::vector<std::pair<std::string, std::string>>& entries,
                                const WriteOptions& options);

/// Step 20 of spec/format.md section 9 on a file with bit 1 whose steps 1-19
/// passed: reads the entry `packed_key_values` of model.key_values (removed
/// from it), checks the range it gives against the three arrays' ranges
/// [offset, offset + stored_length) and the cap (minus `arrays_decoded`, the
/// arrays' decoded bytes), decodes and verifies the bytes and appends their
/// entries to model.key_values. Throws FormatError with the reasons of step 20.
void unpack_key_values(const Source& src, const Header& header, const std::uint64_t (&array_ranges)[3][2],
                       std::uint64_t arrays_decoded, const ReadOptions& options, Model& model);

}  // namespace sogmm::format::detail
