// Container framing: header, trailer and the checks on them.
#include "container.hpp"

#include "crc32c.hpp"

namespace sogmm::format::detail {

void fail(ErrorCode code, const char* reason, const std::string& detail) {
  throw FormatError(code, reason, detail);
}

void write_header(std::uint8_t* out, const Header& h) {
  std::memcpy(out, kMagic.data(), kMagic.size());
  store_le<std::uint16_t>(out + 8, h.major);
  store_le<std::uint16_t>(out + 10, h.minor);
  store_le<std::uint32_t>(out + 12, h.flags);
  store_le<std::uint64_t>(out + 16, h.file_length);
  store_le<std::uint32_t>(out + 24, h.metadata_length);
  store_le<std::uint32_t>(out + 28, h.metadata_crc32c);
}

Header check_header(const std::uint8_t* p, std::size_t prefix_size, std::uint64_t file_size,
                    const std::uint8_t* trailer) {
  const ErrorCode F = ErrorCode::Format;
  // 1. magic (on the bytes there are, so a short non-.sogmm file is "bad_magic")
  const std::size_t n_magic = prefix_size < kMagic.size() ? prefix_size : kMagic.size();
  if (n_magic > 0 && std::memcmp(p, kMagic.data(), n_magic) != 0) {
    bool text_mangled = n_magic >= 4 && std::memcmp(p + 1, "SOG", 3) == 0;
    fail(F, "bad_magic", text_mangled ? "signature damaged (file opened in text mode or sent through a 7-bit channel?)"
                                      : "not a .sogmm file (wrong signature)");
  }
  // 2. minimum size
  if (file_size < kMinFileSize || prefix_size < kHeaderSize) {
    fail(F, "truncated", "file has " + std::to_string(file_size) + " bytes, fewer than the " +
                             std::to_string(kMinFileSize) + " of an empty container");
  }
  Header h;
  h.major = load_le<std::uint16_t>(p + 8);
  h.minor = load_le<std::uint16_t>(p + 10);
  h.flags = load_le<std::uint32_t>(p + 12);
  h.file_length = load_le<std::uint64_t>(p + 16);
  h.metadata_length = load_le<std::uint32_t>(p + 24);
  h.metadata_crc32c = load_le<std::uint32_t>(p + 28);
  // 3. version
  if (h.major != kFormatMajor) {
    fail(F, "unsupported_version", "format version " + std::to_string(h.major) + "." + std::to_string(h.minor) +
                                       " (this reader knows major version " + std::to_string(kFormatMajor) + ")");
  }
  // 4. reserved flags
  if (h.flags != 0) fail(F, "bad_header", "reserved header flags are set");
  // 5. declared length
  if (h.file_length > file_size) {
    fail(F, "truncated", "file has " + std::to_string(file_size) + " bytes but declares " +
                             std::to_string(h.file_length));
  }
  if (h.file_length < file_size) {
    fail(F, "bad_header", "file has " + std::to_string(file_size) + " bytes but declares only " +
                              std::to_string(h.file_length) + " (trailing data)");
  }
  // 6. trailer
  if (std::memcmp(trailer, kEndMagic.data(), kEndMagic.size()) != 0) {
    fail(F, "bad_trailer", "end marker \"SGMM\" missing (truncated or corrupted file)");
  }
  // 7. metadata bounds (pad8 and the sum in 64 bits: L may be up to 2^32 - 1)
  if (h.metadata_length < 8 || h.metadata_length >= kMetadataLengthLimit ||
      kHeaderSize + pad8(h.metadata_length) + kTrailerSize > h.file_length) {
    fail(F, "bad_header",
         "metadata length " + std::to_string(h.metadata_length) +
             (h.metadata_length >= kMetadataLengthLimit ? " is not below the FlatBuffers limit of 2^31 - 1 bytes"
                                                        : " does not fit the file"));
  }
  return h;
}

void check_metadata_crc(const std::uint8_t* metadata, const Header& h) {
  if (crc32c(metadata, h.metadata_length) != h.metadata_crc32c) {
    fail(ErrorCode::Format, "checksum_mismatch", "metadata CRC-32C does not match");
  }
}

}  // namespace sogmm::format::detail
