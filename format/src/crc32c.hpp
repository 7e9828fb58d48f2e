// CRC-32C (Castagnoli), the checksum of the .sogmm format (spec/format.md section 6).
#pragma once

#include <cstddef>
#include <cstdint>

namespace sogmm::format::detail {

/// CRC-32C of `size` bytes: reflected polynomial 0x82F63B78, initial value
/// 0xFFFFFFFF, final XOR 0xFFFFFFFF (the iSCSI / ext4 CRC; check value of
/// "123456789" is 0xE3069283). `crc` continues a previous result.
std::uint32_t crc32c(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace sogmm::format::detail
