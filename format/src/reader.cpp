// The reading procedure of spec/format.md section 9 on a file in memory or on
// disk: from_bytes, load, read_info, read_info_file. Memory: the metadata
// block, the decoded metadata, the float32 model and one array's staging at
// most (spec/format.md section 8); the file itself is never held whole.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "canonical_bytes.hpp"
#include "checks.hpp"
#include "container.hpp"
#include "crc32c.hpp"
#include "decode.hpp"
#include "frame_record.hpp"
#include "packed_key_values.hpp"
#include "quantized_components.hpp"
#include "schema.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/format.hpp"
#include "source.hpp"

namespace sogmm::format {
namespace detail {
namespace {

constexpr bool kBigEndian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;
// The features_required bits a map delta's reader knows (spec/format.md
// sections 2.5 and 2.5.1): a model reader's and map_delta.
// Every bit this library knows, a delta's included: what a delta reader and
// a metadata-only read accept before telling a model from a delta.
constexpr std::uint64_t kDeltaFeatures = kKnownFeatures | kFeatureMapDelta;
// A delta keeps its floats and its frame lines as text (its digest covers
// them; spec/format.md 2.5 and 7): quantized components (bit 2) and a frame
// record (bit 3) are model features that a delta must not carry.
constexpr std::uint64_t kModelOnlyFeatures = kFeatureQuantizedComponents | kFeatureFrameRecord;
const char* const kNames[3] = {"weights", "means", "covariances"};

// Steps 1-16: the header and the trailer first, then the metadata block, read
// only once its length is known to fit the file.
ParsedMetadata read_metadata(const Source& src, const ReadOptions& options,
                             std::uint64_t known_features = kKnownFeatures) {
  const std::uint64_t size = src.size();
  std::uint8_t prefix[kHeaderSize] = {};
  const std::size_t prefix_size = size < kHeaderSize ? static_cast<std::size_t>(size) : kHeaderSize;
  src.read(0, prefix, prefix_size);
  std::uint8_t trailer[kTrailerSize] = {};
  if (size >= kTrailerSize) src.read(size - kTrailerSize, trailer, kTrailerSize);
  const Header h = check_header(prefix, prefix_size, size, trailer);
  // 8-byte aligned, so that every FlatBuffers scalar read is aligned.
  std::vector<std::uint64_t> block(static_cast<std::size_t>(pad8(h.metadata_length) / 8));
  auto* bytes = reinterpret_cast<std::uint8_t*>(block.data());
  src.read(kHeaderSize, bytes, h.metadata_length);
  if (options.verify_checksums) check_metadata_crc(bytes, h);
  return parse_metadata(bytes, h, options, known_features);
}

// Steps 17-18 for one array: its values as float32 at `out` (rows x cols, in
// canonical order). F32 arrays are decoded in place; F64 ones through their
// canonical bytes, then rounded to nearest float32 (IEEE 754: overflow gives
// an infinity, which step 19 rejects).
void read_array(const Source& src, const ArrayRecord& r, std::uint64_t rows, std::uint64_t cols, bool verify,
                const char* name, float* out) {
  const bool f64 = r.dtype == kDTypeF64;
  const Shape shape{rows, cols, f64 ? 8u : 4u};
  const Encoding encoding{r.order, r.filter, r.codec};
  std::vector<std::uint8_t> staging(f64 ? static_cast<std::size_t>(shape.bytes()) : 0);
  std::uint8_t* canonical = f64 ? staging.data() : reinterpret_cast<std::uint8_t*>(out);
  decode_array(src, r.offset, r.stored_length, shape, encoding, canonical);
  if (verify && crc32c(canonical, static_cast<std::size_t>(shape.bytes())) != r.crc32c) {
    fail(ErrorCode::Format, "checksum_mismatch", std::string(name) + ": CRC-32C of the decoded bytes does not match");
  }
  const std::uint64_t n = rows * cols;
  if (f64) {
    static_assert(std::numeric_limits<float>::is_iec559, "IEEE 754 rounding from binary64 to binary32");
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::uint64_t bits = load_le<std::uint64_t>(canonical + 8 * i);
      double d;
      std::memcpy(&d, &bits, 8);
      out[i] = static_cast<float>(d);
    }
  } else if constexpr (kBigEndian) {
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::uint32_t bits = load_le<std::uint32_t>(canonical + 4 * i);
      std::memcpy(out + i, &bits, 4);
    }
  }
}

// UPPER_PACKED -> full: 10 values per component at the start of `cov` become
// 16. Backwards, so that no component overwrites one not yet expanded
// (component k's 16 values start at 16 k >= the end of every packed j < k).
void expand_upper_in_place(float* cov, std::uint64_t m) {
  constexpr int kUpper[10][2] = {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 1}, {1, 2}, {1, 3}, {2, 2}, {2, 3}, {3, 3}};
  for (std::uint64_t k = m; k-- > 0;) {
    float packed[10];
    std::memcpy(packed, cov + 10 * k, sizeof packed);
    float* full = cov + 16 * k;
    for (int t = 0; t < 10; ++t) {
      full[kUpper[t][0] * 4 + kUpper[t][1]] = full[kUpper[t][1] * 4 + kUpper[t][0]] = packed[t];
    }
  }
}

// CRC-32C of float32 values' canonical bytes (section 5.2).
std::uint32_t crc_of_floats(const std::vector<float>& v) {
  const std::vector<std::uint8_t> bytes = canonical_bytes<float>(v.data(), v.size());
  return crc32c(bytes.data(), bytes.size());
}

// Steps 17, 17b and 18 of a file with quantized components (section 5.7):
// every array's codes, then the model they decode to, then each array's
// CRC-32C over the canonical float32 bytes of that model.
void read_quantized(const Source& src, const ParsedMetadata& meta, std::uint64_t m, bool verify, Gmm& g) {
  ComponentCodes codes;
  for (int i = 0; i < 3; ++i) {
    const ArrayRecord& r = meta.arrays[i];
    const Shape shape{m, kCodeColumns[i], 4};
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(shape.bytes()));
    decode_array(src, r.offset, r.stored_length, shape, Encoding{r.order, r.filter, r.codec}, bytes.data());
    std::vector<std::int32_t>& c = codes.arrays[i];
    c.resize(static_cast<std::size_t>(m * kCodeColumns[i]));
    for (std::size_t t = 0; t < c.size(); ++t) c[t] = unzigzag(load_le<std::uint32_t>(&bytes[4 * t]));
  }
  dequantize(codes, m, g);
  if (!verify) return;
  const std::uint32_t crcs[3] = {crc_of_floats(g.weights), crc_of_floats(g.means),
                                 crc_of_floats(pack_upper(g.covariances.data(), g.size()))};
  for (int i = 0; i < 3; ++i) {
    if (crcs[i] != meta.arrays[i].crc32c) {
      fail(ErrorCode::Format, "checksum_mismatch",
           std::string(kNames[i]) + ": CRC-32C of the decoded values does not match");
    }
  }
}

}  // namespace

// The whole procedure. *info (if not null) gets the file information, with
// its `metadata` left default: the returned model holds the metadata. With
// `delta`, the file must be a map delta (spec/format.md section 2.5): its
// components are checked as a delta's and returned as stored (a symmetric
// part would change the bits the receiver must reproduce).
Model read_model(const Source& src, const ReadOptions& options, FileInfo* info, bool delta) {
  ParsedMetadata meta = read_metadata(src, options, delta ? kDeltaFeatures : kKnownFeatures);
  if (delta && (meta.info.features_required & kFeatureMapDelta) == 0)
    fail(ErrorCode::Format, "not_a_delta", "the file is a model, not a map delta (feature bit 0 is not set)");
  if (delta && (meta.info.features_required & kModelOnlyFeatures) != 0)
    fail(ErrorCode::Format, "unsupported_feature",
         "a map delta with feature bit 2 (quantized_components) or 3 (frame_record), which only a model may use");
  const std::uint64_t m = meta.info.n_components;  // its arrays fit the cap (step 15)
  Model model = std::move(meta.info.metadata);
  Gmm& g = model.gmm;
  g.resize(static_cast<std::size_t>(m));
  float* const dest[3] = {g.weights.data(), g.means.data(), g.covariances.data()};
  if (meta.quantized) {
    read_quantized(src, meta, m, options.verify_checksums, g);
  } else {
    for (int i = 0; i < 3; ++i) {
      read_array(src, meta.arrays[i], m, columns(i, meta.packed), options.verify_checksums, kNames[i], dest[i]);
    }
    if (meta.packed) expand_upper_in_place(g.covariances.data(), m);
  }
  check_values(g, delta);  // 19
  if (!meta.packed && !delta) symmetrize(g);
  const std::uint64_t features = meta.info.features_required;
  if (features & (kFeaturePackedKeyValues | kFeatureFrameRecord)) {
    Header h;
    h.file_length = meta.info.file_length;
    h.metadata_length = static_cast<std::uint32_t>(meta.info.metadata_length);
    std::uint64_t ranges[3][2], decoded = 0;
    for (int i = 0; i < 3; ++i) {
      ranges[i][0] = meta.arrays[i].offset;
      ranges[i][1] = meta.arrays[i].stored_length;
      decoded += meta.arrays[i].decoded_length;  // at most the cap (step 15)
    }
    std::uint64_t packed_begin = h.file_length - kTrailerSize;
    if (features & kFeaturePackedKeyValues) {  // 20
      const PackedExtent packed = unpack_key_values(src, h, ranges, decoded, options, model);
      packed_begin -= packed.stored;
      decoded += packed.decoded;  // with the arrays', at most the cap (step 20b)
    }
    if (features & kFeatureFrameRecord) unpack_frame_record(src, h, ranges, packed_begin, decoded, options, model);  // 21
  }
  if (info != nullptr) {
    *info = std::move(meta.info);
    info->metadata = Model{};
  }
  return model;
}

namespace {

const std::uint8_t* bytes_of(const void* data, std::size_t size, const char* who) {
  if (data == nullptr && size != 0) throw Error(ErrorCode::InvalidArgument, std::string(who) + ": null data");
  return static_cast<const std::uint8_t*>(data);
}

}  // namespace
}  // namespace detail

Model from_bytes(const void* data, std::size_t size, const ReadOptions& options) {
  const detail::MemorySource src(detail::bytes_of(data, size, "from_bytes"), size);
  return detail::read_model(src, options, nullptr, false);
}

FileInfo read_info(const void* data, std::size_t size, const ReadOptions& options) {
  const detail::MemorySource src(detail::bytes_of(data, size, "read_info"), size);
  return detail::read_metadata(src, options, detail::kDeltaFeatures).info;
}

Model load(const std::string& path, const ReadOptions& options) { return load(path, options, nullptr); }

Model load(const std::string& path, const ReadOptions& options, FileInfo* info) {
  const detail::FileSource src(path);
  return detail::read_model(src, options, info, false);
}

FileInfo read_info_file(const std::string& path, const ReadOptions& options) {
  const detail::FileSource src(path);
  return detail::read_metadata(src, options, detail::kDeltaFeatures).info;
}

}  // namespace sogmm::format
