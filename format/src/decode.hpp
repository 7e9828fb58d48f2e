// Step 17 of the reading procedure (spec/format.md section 9): stored bytes
// of one array -> its canonical bytes, streamed from the file into the
// caller's buffer so that decoding costs little more than the output itself.
#pragma once

#include <cstdint>

#include "codec.hpp"
#include "source.hpp"

namespace sogmm::format::detail {

/// Decodes the stored bytes of one array, read from `src` at [offset,
/// offset + stored_length), into its canonical bytes at `out` (exactly
/// shape.bytes() bytes, allocated by the caller); the filter and the element
/// order are undone while writing. Besides `out` it allocates, per zstd
/// frame, at most the smaller of the frame's content and its window (none
/// when the order and the filter are the identity: frames then decode in
/// place), and about 300 KiB of fixed buffers. Throws
/// FormatError("decompression_failed") when the data is not exactly
/// shape.bytes() bytes of valid frames; never writes past `out`.
void decode_array(const Source& src, std::uint64_t offset, std::uint64_t stored_length, const Shape& shape,
                  const Encoding& encoding, std::uint8_t* out);

}  // namespace sogmm::format::detail
