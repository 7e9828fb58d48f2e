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

// Four decimal counts "codec stored decoded crc", digits only, 1-19 each.
void parse_entry(const std::string& text, std::uint64_t (&out)[4]) {
  std::size_t at = 0;
  for (int i = 0; i < 4; ++i) {
    const std::size_t end = i < 3 ? text.find(' ', at) : text.size();
    if (end == std::string::npos) bad_entry("'" + text + "' is not four counts separated by single spaces");
    const std::string token = text.substr(at, end - at);
    if (token.empty() || token.size() > 19 || token.find_first_not_of("0123456789") != std::string::npos)
      bad_entry("'" + text + "' is not four decimal counts");
    out[i] = std::stoull(token);
    at = end + 1;
  }
}

}  // namespace

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

void unpack_key_values(const Source& src, const Header& header, const std::uint64_t (&array_ranges)[3][2],
                       std::uint64_t arrays_decoded, const ReadOptions& options, Model& model) {
  // 20a. the entry
  auto it = std::find_if(model.key_values.begin(), model.key_values.end(),
                         [](const auto& kv) { return kv.first == kPackedKeyValuesKey; });
  if (it == model.key_values.end()) bad_entry("missing, but feature bit 1 (packed_key_values) is set");
  std::uint64_t v[4];
  parse_entry(it->second, v);
  const std::uint64_t codec = v[0], stored = v[1], decoded = v[2], crc = v[3];
  if (codec > 1) bad_entry("codec " + std::to_string(codec) + " is not 0 (none) or 1 (zstd)");
  if (crc > 0xFFFFFFFFu) bad_entry("crc32c " + std::to_string(crc) + " is above 2^32 - 1");
  if (decoded < 2) bad_entry("decoded length " + std::to_string(decoded) + " holds no entry");
  model.key_values.erase(it);
  // 20b. the cap, with the arrays' bytes (each below 10^19, so no overflow)
  if (decoded > options.max_decoded_bytes || arrays_decoded > options.max_decoded_bytes - decoded)
    fail(ErrorCode::Limit, "limit",
         "arrays and packed key/values declare " + std::to_string(arrays_decoded) + " + " + std::to_string(decoded) +
             " decoded bytes, over the cap of " + std::to_string(options.max_decoded_bytes));
  // 20c. layout: the last stored bytes of the body
  const std::uint64_t end = header.file_length - kTrailerSize;
  if (stored > end - body_start(header)) fail(F, "bad_layout", "packed key/values: stored bytes lie outside the body");
  const std::uint64_t begin = end - stored;
  if (codec == kCodecNone && stored != decoded)
    fail(F, "bad_layout", "packed key/values: uncompressed but stored length differs from decoded length");
  for (const auto& r : array_ranges) {
    if (stored > 0 && r[1] > 0 && begin < r[0] + r[1] && r[0] < end)
      fail(F, "bad_layout", "packed key/values overlap an array");
  }
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
}

}  // namespace sogmm::format::detail
