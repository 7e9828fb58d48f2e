// Array encoding pipeline (spec/format.md section 5): element order,
// byte-stream split and zstd framing (decoding: decode.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sogmm::format::detail {

// Enum values as in spec/sogmm.fbs (kept numeric here so this file does not
// depend on generated code).
enum : std::uint8_t { kDTypeF32 = 0, kDTypeF64 = 1 };
enum : std::uint8_t { kOrderComponentMajor = 0, kOrderColumnMajor = 1 };
enum : std::uint8_t { kFilterNone = 0, kFilterByteStreamSplit = 1, kFilterQuantized = 2 };
enum : std::uint8_t { kCodecNone = 0, kCodecZstd = 1 };

/// How one array is encoded.
struct Encoding {
  std::uint8_t order = kOrderComponentMajor;
  std::uint8_t filter = kFilterNone;
  std::uint8_t codec = kCodecNone;
};

/// Shape of an array: `rows` components of `cols` elements of `width` bytes.
struct Shape {
  std::uint64_t rows = 0;
  std::uint64_t cols = 0;
  std::uint64_t width = 0;
  std::uint64_t bytes() const { return rows * cols * width; }
};

/// Canonical bytes (component-major, little-endian) -> stored bytes.
/// With the zstd codec and the byte-stream split, each of the `width`
/// streams becomes its own zstd frame (frames are concatenated), unless
/// `one_frame`: then all streams go into one frame (quantized codes, whose
/// arrays are small enough that a frame header per stream would show).
std::vector<std::uint8_t> encode_array(const std::vector<std::uint8_t>& canonical, const Shape& shape,
                                       const Encoding& encoding, int zstd_level, bool one_frame = false);

}  // namespace sogmm::format::detail
