// Packed key/values of a map delta (packed_key_values.hpp, spec/format.md
// section 2.5.1 and step 20 of section 9).
#include "packed_key_values.hpp"

#include <algorithm>
#include <string>

#include "codec.hpp"
#include "crc32c.hpp"
#include "decode.hpp"
#include "sogmm/metadata_string.hpp"

namespace sogmm::format::detail {
namespace {

const ErrorCode F = ErrorCode::Format;

[[noreturn]] void bad_entry(const std::string& why) {
  fail(F, "bad_metadata", std::string("key ") + kPackedKeyValuesKey + ": " + why);
}

}  // namespace

std::uint64_t body_range(const Header& header, const BodyLocator& loc, std::uint64_t end,
                         const std::uint64_t (&array_ranges)[3][2], std::uint64_t decoded_so_far,
                         const ReadOptions& options, const std::string& what) {
  // The cap (each count below 10^19 or the cap, so no overflow).
  if (loc.decoded > options.max_decoded_bytes || decoded_so_far > options.max_decoded_bytes - loc.decoded)
    fail(ErrorCode::Limit, "limit",
         "arrays and " + what + " declare " + std::to_string(decoded_so_far) + " + " + std::to_string(loc.decoded) +
             " decoded bytes, over the cap of " + std::to_string(options.max_decoded_bytes));
  if (loc.stored > end - body_start(header)) fail(F, "bad_layout", what + ": stored bytes lie outside the body");
  const std::uint64_t begin = end - loc.stored;
  if (loc.codec == kCodecNone && loc.stored != loc.decoded)
    fail(F, "bad_layout", what + ": uncompressed but stored length differs from decoded length");
  for (const auto& r : array_ranges) {
    if (loc.stored > 0 && r[1] > 0 && begin < r[0] + r[1] && r[0] < end) fail(F, "bad_layout", what + " overlap an array");
  }
  return begin;
}

BodyLocator parse_locator(const char* key, const std::string& text) {
  auto bad = [key](const std::string& why) { fail(F, "bad_metadata", std::string("key ") + key + ": " + why); };
  std::uint64_t out[4];
  std::size_t at = 0;
  for (int i = 0; i < 4; ++i) {
    const std::size_t end = i < 3 ? text.find(' ', at) : text.size();
    if (end == std::string::npos) bad("'" + text + "' is not four counts separated by single spaces");
    const std::string token = text.substr(at, end - at);
    if (token.empty() || token.size() > 19 || token.find_first_not_of("0123456789") != std::string::npos)
      bad("'" + text + "' is not four decimal counts");
    out[i] = std::stoull(token);
    at = end + 1;
  }
  if (out[0] > 1) bad("codec " + std::to_string(out[0]) + " is not 0 (none) or 1 (zstd)");
  if (out[3] > 0xFFFFFFFFu) bad("crc32c " + std::to_string(out[3]) + " is above 2^32 - 1");
  return BodyLocator{out[0], out[1], out[2], out[3]};
}

PackedKeyValues pack_key_values(const std::vector<std::pair<std::string, std::string>>& entries,
                                const WriteOptions& options) {
  std::vector<std::uint8_t> decoded;
  for (const auto& kv : entries) {
    for (const std::string* s : {&kv.first, &kv.second}) {
      decoded.insert(decoded.end(), s->begin(), s->end());
      decoded.push_back(0);
    }
  }
  PackedKeyValues out;
  int codec = kCodecNone;
  if (options.compress) {
    const Shape bytes{decoded.size(), 1, 1};
    std::vector<std::uint8_t> z = encode_array(decoded, bytes, Encoding{kOrderComponentMajor, kFilterNone, kCodecZstd},
                                               options.zstd_level);
    if (z.size() < decoded.size()) {
      out.stored = std::move(z);
      codec = kCodecZstd;
    }
  }
  if (codec == kCodecNone) out.stored = decoded;
  out.entry = {kPackedKeyValuesKey, std::to_string(codec) + " " + std::to_string(out.stored.size()) + " " +
                                        std::to_string(decoded.size()) + " " +
                                        std::to_string(crc32c(decoded.data(), decoded.size()))};
  return out;
}

PackedExtent unpack_key_values(const Source& src, const Header& header, const std::uint64_t (&array_ranges)[3][2],
                               std::uint64_t arrays_decoded, const ReadOptions& options, Model& model) {
  // 20a. the entry
  auto it = std::find_if(model.key_values.begin(), model.key_values.end(),
                         [](const auto& kv) { return kv.first == kPackedKeyValuesKey; });
  if (it == model.key_values.end()) bad_entry("missing, but feature bit 1 (packed_key_values) is set");
  const BodyLocator loc = parse_locator(kPackedKeyValuesKey, it->second);
  const std::uint64_t codec = loc.codec, stored = loc.stored, decoded = loc.decoded, crc = loc.crc;
  if (decoded < 2) bad_entry("decoded length " + std::to_string(decoded) + " holds no entry");
  model.key_values.erase(it);
  // 20b-c. the cap, and the last stored bytes of the body
  const std::uint64_t end = header.file_length - kTrailerSize;
  const std::uint64_t begin =
      body_range(header, loc, end, array_ranges, arrays_decoded, options, "packed key/values");
  // 20d-e. decoding and CRC-32C (the array pipeline on bytes)
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(decoded));
  decode_array(src, begin, stored, Shape{decoded, 1, 1},
               Encoding{kOrderComponentMajor, kFilterNone, static_cast<std::uint8_t>(codec)}, bytes.data());
  if (options.verify_checksums && crc32c(bytes.data(), bytes.size()) != crc)
    fail(F, "checksum_mismatch", "packed key/values: CRC-32C of the decoded bytes does not match");
  // 20f. entries: key NUL value NUL ...
  if (bytes.back() != 0 || std::count(bytes.begin(), bytes.end(), 0) % 2 != 0)
    fail(F, "bad_metadata", "packed key/values: not a sequence of key NUL value NUL");
  std::vector<std::string> strings;
  for (auto p = bytes.begin(); p != bytes.end();) {
    const auto nul = std::find(p, bytes.end(), 0);
    strings.emplace_back(p, nul);
    const std::string problem = metadata_string_problem(strings.back());
    if (!problem.empty()) fail(F, "bad_metadata", "packed key/values: string " + std::to_string(strings.size() - 1) + ": " + problem);
    p = nul + 1;
  }
  for (std::size_t i = 0; i < strings.size(); i += 2) model.key_values.emplace_back(std::move(strings[i]), std::move(strings[i + 1]));
  return PackedExtent{stored, decoded};
}

}  // namespace sogmm::format::detail
