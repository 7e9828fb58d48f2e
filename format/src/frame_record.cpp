// The binary frame record of a map file (frame_record.hpp, spec/format.md
// section 2.3.2 and step 21 of section 9).
#include "frame_record.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "canonical_bytes.hpp"
#include "codec.hpp"
#include "crc32c.hpp"
#include "decode.hpp"
#include "packed_key_values.hpp"

namespace sogmm::format::detail {
namespace {

const ErrorCode F = ErrorCode::Format;
constexpr std::uint64_t kColumns = 15;  // n_points, n_novel, 12 pose entries, n_components
constexpr double kMaxCount = 9007199254740992.0;  // 2^53: every count up to it is exact in binary64
// Column-major and byte-stream split, as the component arrays: each column's
// bytes of one significance lie together, so zstd finds the zero low bytes
// of counts and rounded poses.
const Encoding kLayout{kOrderColumnMajor, kFilterByteStreamSplit, kCodecNone};

// Appends line `index` of the text from a row of the record.
void append_line(std::string& text, std::uint64_t index, const double* row) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%" PRIu64 " %" PRIu64 " %" PRIu64, index, static_cast<std::uint64_t>(row[0]),
                static_cast<std::uint64_t>(row[1]));
  text += buf;
  for (int i = 2; i < 14; ++i) {
    std::snprintf(buf, sizeof buf, " %.17g", row[i]);
    text += buf;
  }
  std::snprintf(buf, sizeof buf, " %" PRIu64 "\n", static_cast<std::uint64_t>(row[14]));
  text += buf;
}

// A count of the text: 1 to 16 digits, at most 2^53.
bool parse_count(const std::string& token, double& out) {
  if (token.empty() || token.size() > 16 || token.find_first_not_of("0123456789") != std::string::npos) return false;
  const double v = static_cast<double>(std::strtoull(token.c_str(), nullptr, 10));
  if (v > kMaxCount) return false;
  out = v;
  return true;
}

// The rows of `text`, or false when a line is not 16 space-separated numbers
// with index = its line number. Exactness is checked by the caller.
bool parse_rows(const std::string& text, std::vector<double>& rows) {
  std::size_t at = 0;
  for (std::uint64_t line = 0; at < text.size(); ++line) {
    const std::size_t eol = text.find('\n', at);
    if (eol == std::string::npos) return false;
    double row[kColumns + 1];
    std::size_t p = at;
    for (std::uint64_t c = 0; c <= kColumns; ++c) {
      const std::size_t end = c < kColumns ? text.find(' ', p) : eol;
      if (end == std::string::npos || end > eol) return false;
      const std::string token = text.substr(p, end - p);
      const bool pose = c >= 3 && c < kColumns;
      if (pose) {
        char* stop = nullptr;
        row[c] = std::strtod(token.c_str(), &stop);
        if (token.empty() || *stop != '\0' || !std::isfinite(row[c])) return false;
      } else if (!parse_count(token, row[c])) {
        return false;
      }
      p = end + 1;
    }
    if (row[0] != static_cast<double>(line)) return false;
    rows.insert(rows.end(), row + 1, row + kColumns + 1);
    at = eol + 1;
  }
  return !rows.empty();
}

}  // namespace

std::vector<double> frame_rows(const std::string& text) {
  std::vector<double> rows;
  if (!parse_rows(text, rows)) return {};
  const std::uint64_t n = rows.size() / kColumns;
  std::string again;
  again.reserve(text.size());
  for (std::uint64_t r = 0; r < n; ++r) append_line(again, r, &rows[r * kColumns]);
  if (again != text) return {};  // the reader would write other digits
  return rows;
}

std::optional<FrameRecord> encode_frame_record(const std::string& text, const WriteOptions& options) {
  const std::vector<double> rows = frame_rows(text);
  if (rows.empty()) return std::nullopt;
  return encode_frame_rows(rows, options);
}

FrameRecord encode_frame_rows(const std::vector<double>& rows, const WriteOptions& options) {
  const std::vector<std::uint8_t> canonical = canonical_bytes<double>(rows.data(), rows.size());
  const Shape shape{rows.size() / kColumns, kColumns, 8};
  FrameRecord out;
  Encoding e = kLayout;
  out.stored = encode_array(canonical, shape, e, options.zstd_level);  // split, uncompressed
  if (options.compress) {
    // One zstd frame for all 8 byte streams, not one each as the arrays: a
    // frame costs ~12 bytes, a third of a two-frame record.
    std::vector<std::uint8_t> z = encode_array(out.stored, Shape{out.stored.size(), 1, 1},
                                               Encoding{kOrderComponentMajor, kFilterNone, kCodecZstd}, options.zstd_level);
    if (z.size() < out.stored.size()) {
      out.stored = std::move(z);
      e.codec = kCodecZstd;
    }
  }
  out.entry = {kFrameRecordKey, std::to_string(e.codec) + " " + std::to_string(out.stored.size()) + " " +
                                    std::to_string(canonical.size()) + " " +
                                    std::to_string(crc32c(canonical.data(), canonical.size()))};
  return out;
}

void unpack_frame_record(const Source& src, const Header& header, const std::uint64_t (&array_ranges)[3][2],
                         std::uint64_t packed_begin, std::uint64_t decoded_so_far, const ReadOptions& options,
                         Model& model) {
  // 21a. the entry
  auto it = std::find_if(model.key_values.begin(), model.key_values.end(),
                         [](const auto& kv) { return kv.first == kFrameRecordKey; });
  if (it == model.key_values.end())
    fail(F, "bad_metadata", std::string("key ") + kFrameRecordKey + ": missing, but feature bit 3 (frame_record) is set");
  const BodyLocator loc = parse_locator(kFrameRecordKey, it->second);
  if (loc.decoded == 0 || loc.decoded % (kColumns * 8) != 0)
    fail(F, "bad_metadata", std::string("key ") + kFrameRecordKey + ": decoded length " + std::to_string(loc.decoded) +
                                " is not a positive multiple of 120 (15 binary64 values a frame)");
  // 21b-c. the cap, and the stored bytes right before the packed key/values
  const std::uint64_t begin =
      body_range(header, loc, packed_begin, array_ranges, decoded_so_far, options, "frame record");
  // 21d-e. decoding (the array pipeline) and CRC-32C of the canonical bytes
  const std::uint64_t n = loc.decoded / (kColumns * 8);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(loc.decoded));
  Encoding e = kLayout;
  e.codec = static_cast<std::uint8_t>(loc.codec);
  decode_array(src, begin, loc.stored, Shape{n, kColumns, 8}, e, bytes.data());
  if (options.verify_checksums && crc32c(bytes.data(), bytes.size()) != loc.crc)
    fail(F, "checksum_mismatch", "frame record: CRC-32C of the decoded bytes does not match");
  // 21f. values: counts are integers in [0, 2^53], pose entries finite
  std::vector<double> row(kColumns);
  std::string text;
  for (std::uint64_t r = 0; r < n; ++r) {
    for (std::uint64_t c = 0; c < kColumns; ++c) {
      const std::uint64_t bits = load_le<std::uint64_t>(&bytes[8 * (r * kColumns + c)]);
      std::memcpy(&row[c], &bits, 8);
      const bool count = c < 2 || c == kColumns - 1;
      const bool ok = count ? (row[c] >= 0 && row[c] <= kMaxCount && std::floor(row[c]) == row[c])
                            : std::isfinite(row[c]);
      if (!ok)
        fail(F, "bad_metadata", "frame record: frame " + std::to_string(r) + ", column " + std::to_string(c) +
                                    (count ? " is not a count in [0, 2^53]" : " is not finite"));
    }
    append_line(text, r, row.data());
  }
  *it = {kMapFramesKey, std::move(text)};
}

}  // namespace sogmm::format::detail
