// The writer: to_bytes() and save(). A model is checked against everything a
// reader would reject, every limit included, before any byte is produced; the
// encoded file is then held as its parts (header, metadata block, arrays) and
// streamed to disk or copied once into memory, so a save needs little more
// memory than the file it writes.
#include <algorithm>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "canonical_bytes.hpp"
#include "checks.hpp"
#include "codec.hpp"
#include "container.hpp"
#include "crc32c.hpp"
#include "frame_record.hpp"
#include "internal.hpp"
#include "packed_key_values.hpp"
#include "quantized_components.hpp"
#include "schema.hpp"
#include "strings.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/format.hpp"
#include "sogmm/options.hpp"

namespace sogmm::format {
namespace detail {
namespace {

bool bit_symmetric(const std::vector<float>& cov, std::size_t m) {
  for (std::size_t k = 0; k < m; ++k) {
    const float* c = cov.data() + 16 * k;
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        if (std::memcmp(&c[i * 4 + j], &c[j * 4 + i], sizeof(float)) != 0) return false;
      }
    }
  }
  return true;
}

// The writer's checks: what a reader would reject, a writer refuses.
void validate_for_write(const Model& model, bool delta) {
  const Gmm& g = model.gmm;
  const std::size_t m = g.weights.size();
  if (m == 0 && !delta) fail(ErrorCode::InvalidData, "empty", "model has no components (M = 0)");
  if (g.means.size() != 4 * m || g.covariances.size() != 16 * m) {
    fail(ErrorCode::InvalidData, "length_mismatch",
         "array lengths disagree with M = " + std::to_string(m) + ": " + std::to_string(g.means.size()) +
             " mean values, " + std::to_string(g.covariances.size()) + " covariance values");
  }
  check_strings(model, ErrorCode::InvalidData);
  check_metadata_numbers(model, ErrorCode::InvalidData);
  if (model.pose) check_pose(*model.pose);
  check_values(g, delta);
}

// The producer version a file records: the model's, or this library's.
std::string producer_version(const Model& model) {
  return model.producer_version.empty() ? std::string(sogmm::version_string()) : model.producer_version;
}

// Bytes a FlatBuffers string of n bytes takes at most (length, NUL,
// alignment) and at least (length and NUL).
constexpr std::uint64_t kStringMaxOverhead = 8;
constexpr std::uint64_t kStringMinOverhead = 5;
// A KeyValue table with its vtable, padding and vector slot, at most / at least.
constexpr std::uint64_t kKeyValueMaxBytes = 36;
constexpr std::uint64_t kKeyValueMinBytes = 16;
// Everything else of a block (root, array, fit and camera tables, pose, axis
// vectors, the builder's scratch space), at most.
constexpr std::uint64_t kFixedMaxBytes = 4096;

// Metadata-size bounds computed from the strings alone.
struct MetadataBounds {
  std::uint64_t lower = 0;  ///< the block has at least this many bytes
  std::uint64_t upper = 0;  ///< and at most this many
};

MetadataBounds metadata_bounds(const Model& model) {
  std::uint64_t text = model.producer_name.size() + producer_version(model).size();
  for (const auto& kv : model.key_values) text += kv.first.size() + kv.second.size();
  const std::uint64_t strings = 2 + 2 * static_cast<std::uint64_t>(model.key_values.size());
  const std::uint64_t n_kv = model.key_values.size();
  // No overflow: sizes of strings held in memory and a count of at most
  // kMaxMetadataTables (checked before) are far below 2^63.
  return {text + strings * kStringMinOverhead + n_kv * kKeyValueMinBytes,
          text + strings * kStringMaxOverhead + n_kv * kKeyValueMaxBytes + kFixedMaxBytes};
}

// The limits a reader enforces on the metadata block (spec/format.md section
// 4.3): at most kMaxMetadataTables tables and fewer than kMetadataLengthLimit
// bytes. Checked from the counts and string sizes, before anything is built.
MetadataBounds check_metadata_limits(const Model& model) {
  const std::uint64_t tables = 4 + (model.fit.known ? 1 : 0) + (model.camera.known ? 1 : 0) +
                               static_cast<std::uint64_t>(model.key_values.size());
  if (tables > kMaxMetadataTables) {
    fail(ErrorCode::Limit, "limit",
         "the model has " + std::to_string(model.key_values.size()) + " key/value pairs: its metadata would hold " +
             std::to_string(tables) + " tables, more than the " + std::to_string(kMaxMetadataTables) +
             " a reader verifies");
  }
  // Refused when the block could reach the limit (its upper bound), not only
  // when it must (its lower bound): FlatBuffers itself cannot build a buffer
  // of 2^31 bytes (an assertion in debug builds), and building first would
  // allocate ~2 GiB before the exact size is known. This refuses at most a
  // few KiB of metadata below the limit that would have fitted.
  const MetadataBounds bounds = metadata_bounds(model);
  if (bounds.upper >= kMetadataLengthLimit) {
    fail(ErrorCode::Limit, "limit",
         "the metadata (producer strings and key/value pairs) may need up to " + std::to_string(bounds.upper) +
             " bytes; a metadata block must be smaller than 2^31 - 1 bytes");
  }
  return bounds;
}

struct EncodedArray {
  ArrayRecord record;
  std::vector<std::uint8_t> stored;
};

EncodedArray encode_one(const std::vector<float>& values, std::uint64_t cols, const WriteOptions& options) {
  EncodedArray out;
  const bool f64 = options.float64;
  std::vector<std::uint8_t> canonical =
      f64 ? canonical_bytes<double>(values.data(), values.size()) : canonical_bytes<float>(values.data(), values.size());
  const Shape shape{values.size() / cols, cols, f64 ? 8u : 4u};
  out.record.dtype = f64 ? kDTypeF64 : kDTypeF32;
  out.record.decoded_length = canonical.size();
  out.record.crc32c = crc32c(canonical.data(), canonical.size());
  if (options.compress) {
    const Encoding packed{kOrderColumnMajor, kFilterByteStreamSplit, kCodecZstd};
    std::vector<std::uint8_t> z = encode_array(canonical, shape, packed, options.zstd_level);
    if (z.size() < canonical.size()) {
      out.stored = std::move(z);
      out.record.order = packed.order;
      out.record.filter = packed.filter;
      out.record.codec = packed.codec;
    }
  }
  // Otherwise raw: component-major, no filter, no codec.
  if (out.record.codec == kCodecNone) out.stored = std::move(canonical);
  out.record.stored_length = out.stored.size();
  return out;
}

// One array of a quantized file (section 5.7): its codes, zigzagged,
// column-major and byte-stream split in one zstd frame (or raw when that is
// smaller), declared by the canonical float32 bytes they decode to.
EncodedArray encode_codes(const std::vector<std::int32_t>& codes, std::uint64_t cols,
                          const std::vector<float>& decoded, const WriteOptions& options) {
  EncodedArray out;
  const std::vector<std::uint8_t> canonical = canonical_bytes<float>(decoded.data(), decoded.size());
  out.record.dtype = kDTypeF32;
  out.record.decoded_length = canonical.size();
  out.record.crc32c = crc32c(canonical.data(), canonical.size());
  std::vector<std::uint8_t> raw(4 * codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) store_le<std::uint32_t>(&raw[4 * i], zigzag(codes[i]));
  const Shape shape{codes.size() / cols, cols, 4};
  Encoding e{kOrderColumnMajor, kFilterQuantized, kCodecNone};
  out.stored = encode_array(raw, shape, e, options.zstd_level);
  if (options.compress) {
    e.codec = kCodecZstd;
    std::vector<std::uint8_t> z = encode_array(raw, shape, e, options.zstd_level, true);
    if (z.size() < out.stored.size()) {
      out.stored = std::move(z);
      out.record.codec = kCodecZstd;
    }
  }
  out.record.order = e.order;
  out.record.filter = e.filter;
  out.record.stored_length = out.stored.size();
  return out;
}

// The codes of `g` at `precision` and the model they decode to, when a reader
// accepts that model (step 19); else nothing, and the writer stores floats.
std::optional<std::pair<ComponentCodes, Gmm>> quantized(const Gmm& g, double precision) {
  std::optional<ComponentCodes> codes = quantize(g, precision);
  if (!codes) return std::nullopt;
  Gmm decoded;
  decoded.support_size = g.support_size;
  try {
    dequantize(*codes, g.size(), decoded);
    check_values(decoded, false);
  } catch (const Error&) {
    return std::nullopt;
  }
  return std::make_pair(std::move(*codes), std::move(decoded));
}

// An encoded file held as its parts, in file order: header, metadata block,
// zero padding to 8, then the arrays, each at a multiple of 8 and without
// padding after the last, then the end marker.
class EncodedFile {
 public:
  EncodedFile(const Model& model, const WriteOptions& options, const Tweaks& tweaks) {
    // The registry's range (a C API caller is checked when setting it; a C++
    // caller here): infinity would code every component to nothing useful.
    require_option(OptionKey::ARRAY_PRECISION, options.component_precision, "save: component_precision");
    // A map (a model with a `map_frames` text the record reproduces) is
    // written as format 1.3: its frame lines as the binary frame record (bit
    // 3) and every key/value packed in the body (bit 1; spec/format.md 2.3.2).
    Tweaks t = tweaks;
    std::vector<std::pair<std::string, std::string>> key_values;
    // A model that holds the record's locating key itself keeps its text: a
    // reader takes the first `map_frame_record` entry, which would be its own.
    const bool holds_locator_key = std::any_of(model.key_values.begin(), model.key_values.end(),
                                               [](const auto& kv) { return kv.first == kFrameRecordKey; });
    if (t.compact_maps && t.features_required == 0 && !t.pack_key_values && !holds_locator_key) {
      auto it = std::find_if(model.key_values.begin(), model.key_values.end(),
                             [](const auto& kv) { return kv.first == kMapFramesKey; });
      std::optional<FrameRecord> record;
      if (it != model.key_values.end()) record = encode_frame_record(it->second, options);
      if (record) {
        if (t.frame_record_entry) record->entry.second = *t.frame_record_entry;
        frames_ = t.frame_record_stored ? *t.frame_record_stored : std::move(record->stored);
        key_values = model.key_values;
        key_values[static_cast<std::size_t>(it - model.key_values.begin())] = record->entry;
        t.minor = std::max<std::uint16_t>(t.minor, kMinorFrameRecord);
        t.features_required = kFeaturePackedKeyValues | kFeatureFrameRecord;
        t.pack_key_values = true;
      }
    }
    MetadataBounds bounds;
    if (t.validate) {
      validate_for_write(model, (t.features_required & kFeatureMapDelta) != 0);
      bounds = check_metadata_limits(model);
    } else {
      bounds = metadata_bounds(model);
    }
    const Gmm& g = model.gmm;
    const std::size_t m = g.weights.size();
    const bool packed = !t.force_full_layout && g.covariances.size() == 16 * m && bit_symmetric(g.covariances, m);
    // Before any array is encoded: a file a reader would refuse is not written.
    if (t.validate) check_decoded_size(m, packed, options.float64, options.max_decoded_bytes);
    Tweaks tq = t;
    // A map delta keeps its floats: its receiver must reproduce the sender's bits.
    const bool quantize_arrays = options.component_precision > 0 && m > 0 && (t.features_required & kFeatureMapDelta) == 0;
    const auto q = quantize_arrays ? quantized(g, options.component_precision) : std::nullopt;
    if (q) {
      tq.features_required |= kFeatureQuantizedComponents;
      tq.minor = std::max(t.minor, kQuantizedMinor);
      arrays_[kWeights] = encode_codes(q->first.arrays[kWeights], 1, q->second.weights, options);
      arrays_[kMeans] = encode_codes(q->first.arrays[kMeans], 5, q->second.means, options);
      arrays_[kCovariances] = encode_codes(q->first.arrays[kCovariances], 14, pack_upper(q->second.covariances.data(), m),
                                           options);
    } else {
      arrays_[kWeights] = encode_one(g.weights, 1, options);
      arrays_[kMeans] = encode_one(g.means, 4, options);
      arrays_[kCovariances] =
          encode_one(packed ? pack_upper(g.covariances.data(), m) : g.covariances, packed ? 10 : 16, options);
    }
    // The axis lists are fixed (spec/format.md 4.2): a file that only readers
    // of format 1.3 on can read (bit 2 or 3) leaves them out, as format 1.5.
    if (!tq.axis_lists) {
      tq.axis_lists = (tq.features_required & kFeaturesWithoutAxisLists) == 0;
      if (!*tq.axis_lists) tq.minor = std::max(tq.minor, kMinorAxisListsOptional);
    }
    const std::uint64_t n_declared = t.n_components ? *t.n_components : m;
    ArrayRecord records[3];
    for (int i = 0; i < 3; ++i) {
      records[i] = arrays_[i].record;
      if (t.lengths_follow_declared_m) records[i].decoded_length = n_declared * columns(i, packed || q) * (options.float64 ? 8 : 4);
      // A placeholder until the block's length is known: any non-zero value
      // makes the field present, so the block's length does not depend on it.
      records[i].offset = std::uint64_t{1} << 40;
    }
    records[kCovariances].crc32c ^= t.covariance_crc_xor;
    if (t.means_codec) records[kMeans].codec = *t.means_codec;
    if (t.means_offset) records[kMeans].offset = *t.means_offset;

    const std::size_t hint = static_cast<std::size_t>(std::min<std::uint64_t>(bounds.upper, kMetadataLengthLimit));
    if (t.pack_key_values) {
      // The entries go to the body; the metadata keeps the one that finds them.
      packed_kv_ = pack_key_values(frames_.empty() ? model.key_values : key_values, options);
      Model stripped = model;
      stripped.key_values = {packed_kv_.entry};
      metadata_ = build_metadata(stripped, records, n_declared, packed || q, tq, hint);
    } else {
      metadata_ = build_metadata(model, records, n_declared, packed || q, tq, hint);
    }
    if (t.validate && metadata_.size() >= kMetadataLengthLimit) {
      fail(ErrorCode::Limit, "limit",
           "the metadata block would have " + std::to_string(metadata_.size()) +
               " bytes; it must be smaller than 2^31 - 1 bytes");
    }

    std::uint64_t offsets[3];
    std::uint64_t end = kHeaderSize + pad8(metadata_.size());
    for (int i = 0; i < 3; ++i) {
      offsets[i] = end;
      end += arrays_[i].stored.size();
      if (i < 2) end = pad8(end);
    }
    end += frames_.size();            // right before the packed key/values (section 2.3.2)
    end += packed_kv_.stored.size();  // last in the body, unaligned (section 2.5.1)
    const bool patch[3] = {true, !t.means_offset, true};
    set_array_offsets(metadata_.data(), offsets, patch);

    header_.major = t.major;
    header_.minor = tq.minor;
    header_.metadata_length = static_cast<std::uint32_t>(metadata_.size());  // < 2^31 (checked) or a test's tweak
    header_.metadata_crc32c = crc32c(metadata_.data(), metadata_.size());
    header_.file_length = end + kTrailerSize;
  }

  std::uint64_t size() const { return header_.file_length; }

  // Hands the file's bytes, in order, to `sink`.
  void emit(const ByteSink& sink) const {
    static const std::uint8_t kZeros[8] = {};
    std::uint8_t header[kHeaderSize];
    write_header(header, header_);
    sink(header, kHeaderSize);
    sink(metadata_.data(), metadata_.size());
    std::uint64_t at = kHeaderSize + metadata_.size();
    for (int i = 0; i < 3; ++i) {
      sink(kZeros, static_cast<std::size_t>(pad8(at) - at));
      at = pad8(at);
      sink(arrays_[i].stored.data(), arrays_[i].stored.size());
      at += arrays_[i].stored.size();
    }
    sink(frames_.data(), frames_.size());
    sink(packed_kv_.stored.data(), packed_kv_.stored.size());
    sink(kEndMagic.data(), kEndMagic.size());
  }

  std::vector<std::uint8_t> to_vector() const {
    if (size() > std::numeric_limits<std::size_t>::max()) fail(ErrorCode::Limit, "limit", "the file is too large for memory");
    std::vector<std::uint8_t> file(static_cast<std::size_t>(size()));
    std::size_t at = 0;
    emit([&](const std::uint8_t* p, std::size_t n) {
      if (n > 0) std::memcpy(&file[at], p, n);
      at += n;
    });
    return file;
  }

 private:
  Header header_;
  flatbuffers::DetachedBuffer metadata_;
  EncodedArray arrays_[3];
  std::vector<std::uint8_t> frames_;  // the frame record's stored bytes, empty unless a compact map
  PackedKeyValues packed_kv_;         // empty unless Tweaks::pack_key_values
};

}  // namespace

void check_decoded_size(std::uint64_t m, bool packed, bool float64, std::uint64_t cap) {
  // The reader's step 14 arithmetic (schema.cpp), in one dtype.
  std::uint64_t total = 0;
  bool overflow = false;
  for (int i = 0; i < 3 && !overflow; ++i) {
    std::uint64_t values = 0, bytes = 0;
    overflow = !checked::try_mul<std::uint64_t>(m, columns(i, packed), &values) ||
               !checked::try_mul<std::uint64_t>(values, float64 ? 8 : 4, &bytes) ||
               !checked::try_add(total, bytes, &total);
  }
  if (overflow || total > cap) {
    const std::string over = cap == kDefaultMaxDecodedBytes
                                  ? "the 1 GiB (" + std::to_string(cap) + " bytes) cap that readers apply by default"
                                  : "the cap of " + std::to_string(cap) + " bytes given for writing";
    fail(ErrorCode::Limit, "limit",
         "the arrays of " + std::to_string(m) + " components would decode to " +
             (overflow ? std::string("more than 2^64") : std::to_string(total)) + " bytes, over " + over +
             ": a reader with that cap refuses the file. To write it anyway raise the cap on both sides "
             "(WriteOptions::max_decoded_bytes and ReadOptions::max_decoded_bytes; C API and bindings: "
             "SOGMM_OPT_MAX_DECODED_BYTES for save and load)");
  }
}

std::vector<std::uint8_t> encode(const Model& model, const WriteOptions& options, const Tweaks& t) {
  return EncodedFile(model, options, t).to_vector();
}

void refresh_metadata_crc(std::vector<std::uint8_t>& file) {
  const std::uint32_t len = load_le<std::uint32_t>(&file[24]);
  store_le<std::uint32_t>(&file[28], crc32c(&file[kHeaderSize], len));
}

}  // namespace detail

std::vector<std::uint8_t> to_bytes(const Model& model, const WriteOptions& options) {
  return detail::encode(model, options, detail::Tweaks{});
}

void write_file(const std::string& path, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  detail::atomic_write(path, size, [bytes, size](const detail::ByteSink& sink) { sink(bytes, size); });
}

void save(const std::string& path, const Model& model, const WriteOptions& options) {
  const detail::EncodedFile file(model, options, detail::Tweaks{});
  detail::atomic_write(path, file.size(), [&file](const detail::ByteSink& sink) { file.emit(sink); });
}

}  // namespace sogmm::format
