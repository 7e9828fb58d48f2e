// The binary frame record of a map file (spec/format.md section 2.3.2,
// format 1.3, feature bit 3): the `map_frames` text (one line of 16 numbers
// per inserted frame, 17 significant digits per pose entry) stored as an
// F x 15 binary64 matrix, byte-stream split and zstd-compressed like the
// component arrays. On the synthetic loop's 100 frames the text takes 22 KB
// (6.9 KB packed with zstd), the record 4.5 KB, and 1.9 KB once the map
// rounds its poses (MapOptions::component_precision > 0).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "container.hpp"
#include "source.hpp"
#include "sogmm/file_options.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format::detail {

/// features_required bit 3: a key/value entry `map_frame_record` stands for
/// the `map_frames` text, whose numbers are in the body.
inline constexpr std::uint64_t kFeatureFrameRecord = 8;
inline constexpr const char* kFrameRecordKey = "map_frame_record";
inline constexpr const char* kMapFramesKey = "map_frames";

/// The stored bytes of a record and the entry that stands for the text.
struct FrameRecord {
  std::vector<std::uint8_t> stored;
  std::pair<std::string, std::string> entry;
};

/// The record of `text` when reading it back gives `text` byte for byte
/// (lines "i n_points n_novel p0 .. p11 n_components\n", i = 0, 1, ...,
/// counts at most 2^53, pose entries finite and written as C's "%.17g", as
/// sogmm::Map writes them); std::nullopt otherwise (the text then stays text).
std::optional<FrameRecord> encode_frame_record(const std::string& text, const WriteOptions& options);

/// The rows (15 values a frame) of such a text; empty when it is not one.
std::vector<double> frame_rows(const std::string& text);

/// The record of rows of 15 values (any values: the tests and the
/// conformance generator make hostile ones), zstd when options.compress and
/// that is smaller.
FrameRecord encode_frame_rows(const std::vector<double>& rows, const WriteOptions& options);

/// Step 21 of spec/format.md section 9 on a file with bit 3, after step 20:
/// finds the first entry `map_frame_record`, checks its range (ending where
/// the packed key/values begin, `packed_begin`; the body's end without them)
/// against the arrays' ranges and the cap (minus `decoded_so_far`), decodes
/// and verifies the record and replaces the entry by (`map_frames`, text).
/// Throws FormatError with the reasons of step 21.
void unpack_frame_record(const Source& src, const Header& header, const std::uint64_t (&array_ranges)[3][2],
                         std::uint64_t packed_begin, std::uint64_t decoded_so_far, const ReadOptions& options,
                         Model& model);

}  // namespace sogmm::format::detail
