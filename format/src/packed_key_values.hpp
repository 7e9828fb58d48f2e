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

/// The entry that locates bytes in the body: "codec stored_length
/// decoded_length crc32c" (spec/format.md 2.5.1 and 2.3.2).
struct BodyLocator {
  std::uint64_t codec = 0, stored = 0, decoded = 0, crc = 0;
};

/// Parses a locator value: four decimal counts of 1-19 digits separated by
/// single spaces, codec 0 or 1, crc32c below 2^32; else FormatError
/// "bad_metadata" naming `key`.
BodyLocator parse_locator(const char* key, const std::string& text);

/// Steps 20b-c / 21b-c: the cap (the located decoded bytes plus
/// `decoded_so_far`), then the stored range [end - stored, end): inside the
/// body, of the decoded length when raw, overlapping no array's range
/// [offset, offset + stored_length). Returns its start; FormatError "limit"
/// or "bad_layout" naming `what` otherwise.
std::uint64_t body_range(const Header& header, const BodyLocator& loc, std::uint64_t end,
                         const std::uint64_t (&array_ranges)[3][2], std::uint64_t decoded_so_far,
                         const ReadOptions& options, const std::string& what);

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
/// Returns the packed bytes' stored and decoded lengths.
struct PackedExtent {
  std::uint64_t stored = 0, decoded = 0;
};
PackedExtent unpack_key_values(const Source& src, const Header& header, const std::uint64_t (&array_ranges)[3][2],
                               std::uint64_t arrays_decoded, const ReadOptions& options, Model& model);

}  // namespace sogmm::format::detail
