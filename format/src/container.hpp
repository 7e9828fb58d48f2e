// Container framing of a .sogmm file (spec/format.md section 3): the 32-byte
// header, the metadata block, the body and the 4-byte trailer.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sogmm/format.hpp"

namespace sogmm::format::detail {

/// First 8 bytes of every file: 0x89 'S' 'O' 'G' CR LF 0x1A LF.
inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'S', 'O', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
/// Last 4 bytes of every file, also the FlatBuffers file identifier.
inline constexpr std::array<std::uint8_t, 4> kEndMagic = {'S', 'G', 'M', 'M'};
inline constexpr std::size_t kHeaderSize = 32;
inline constexpr std::size_t kTrailerSize = 4;
inline constexpr std::size_t kMinFileSize = kHeaderSize + kTrailerSize;
/// Metadata blocks must be smaller than this: FlatBuffers' limit (offsets are
/// 32-bit signed), FLATBUFFERS_MAX_BUFFER_SIZE, exclusive.
inline constexpr std::uint64_t kMetadataLengthLimit = (std::uint64_t{1} << 31) - 1;
/// features_required bit of a file whose arrays hold quantized component
/// codes (spec/format.md section 5.7, format 1.4).
inline constexpr std::uint64_t kFeatureQuantizedComponents = 4;
/// Feature bits a model reader knows: 1 (packed_key_values) and 3
/// (frame_record) of format 1.3 map files, 2 (quantized_components) of
/// format 1.4 (spec/format.md section 7).
inline constexpr std::uint64_t kKnownFeatures = 2 | kFeatureQuantizedComponents | 8;
/// features_required bit of a map delta (spec/format.md sections 2.5 and 7):
/// known only to the delta reader, so a model reader refuses a delta.
inline constexpr std::uint64_t kFeatureMapDelta = 1;

/// The fixed header fields.
struct Header {
  std::uint16_t major = kFormatMajor;
  std::uint16_t minor = kFormatMinor;
  std::uint32_t flags = 0;
  std::uint64_t file_length = 0;
  std::uint32_t metadata_length = 0;
  std::uint32_t metadata_crc32c = 0;
};

/// Rounds up to a multiple of 8.
inline std::uint64_t pad8(std::uint64_t n) { return (n + 7) & ~std::uint64_t{7}; }

template <typename T>
T load_le(const std::uint8_t* p) {
  T v = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(static_cast<T>(p[i]) << (8 * i));
  return v;
}
template <typename T>
void store_le(std::uint8_t* p, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

/// Throws FormatError(code, reason, detail).
[[noreturn]] void fail(ErrorCode code, const char* reason, const std::string& detail);

/// Serialises a header into 32 bytes.
void write_header(std::uint8_t* out, const Header& header);

/// Steps 1-7 of the reading procedure (spec/format.md section 9) on the
/// first `prefix_size` (at most 32) bytes of a file of `file_size` bytes whose
/// last 4 bytes are `trailer`: magic, size, version, flags, length, trailer
/// and the metadata bounds. Uses nothing but those bytes, so a caller reads
/// the metadata block only once its length is known to fit. Returns the header.
Header check_header(const std::uint8_t* prefix, std::size_t prefix_size, std::uint64_t file_size,
                    const std::uint8_t* trailer);

/// Step 8: the CRC-32C of the metadata block against the header.
void check_metadata_crc(const std::uint8_t* metadata, const Header& header);

/// Offset of the body: header + metadata padded to 8.
inline std::uint64_t body_start(const Header& h) { return kHeaderSize + pad8(h.metadata_length); }

}  // namespace sogmm::format::detail
