// The FlatBuffers wire rules of spec/format.md section 4.3, checked on the
// metadata block before any value is read from it.
#pragma once

#include <cstdint>

namespace sogmm::format::detail {

/// Step 9 (structure): verifies the `length` bytes of the metadata block at
/// `block` (8-byte aligned) against the rules of spec/format.md section 4.3
/// for the schema spec/sogmm.fbs: the file identifier, every offset, table,
/// vtable, field, vector and string reachable through a known field, the
/// nesting depth, the number of table visits and the required arrays. Throws
/// FormatError(bad_metadata) naming the first problem. Fields with ids the
/// schema does not know are not read, so they are not checked.
void verify_wire(const std::uint8_t* block, std::uint64_t length);

}  // namespace sogmm::format::detail
