// Writing: to_bytes / save, built from the container, schema, codec and
// checks pieces (reading is in reader.cpp).
#include "sogmm/format.hpp"

#include <cstring>

#include "checks.hpp"
#include "codec.hpp"
#include "container.hpp"
#include "crc32c.hpp"
#include "internal.hpp"
#include "schema.hpp"
#include "strings.hpp"

namespace sogmm::format {
namespace detail {
namespace {

// Canonical little-endian bytes of float values, as f32 or (exactly widened) f64.
std::vector<std::uint8_t> canonical_bytes(const std::vector<float>& v, bool f64) {
  std::vector<std::uint8_t> out(v.size() * (f64 ? 8 : 4));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (f64) {
      std::uint64_t bits;
      const double d = v[i];
      std::memcpy(&bits, &d, 8);
      store_le<std::uint64_t>(&out[i * 8], bits);
    } else {
      std::uint32_t bits;
      std::memcpy(&bits, &v[i], 4);
      store_le<std::uint32_t>(&out[i * 4], bits);
    }
  }
  return out;
}

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

std::vector<float> pack_upper(const std::vector<float>& cov, std::size_t m) {
  std::vector<float> out;
  out.reserve(10 * m);
  for (std::size_t k = 0; k < m; ++k) {
    for (int i = 0; i < 4; ++i) {
      for (int j = i; j < 4; ++j) out.push_back(cov[16 * k + 4 * i + j]);
    }
  }
  return out;
}

// The writer's checks: what a reader would reject, a writer refuses.
void validate_for_write(const Model& model) {
  const Gmm& g = model.gmm;
  const std::size_t m = g.weights.size();
  if (m == 0) fail(ErrorCode::InvalidData, "empty", "model has no components (M = 0)");
  if (g.means.size() != 4 * m || g.covariances.size() != 16 * m) {
    fail(ErrorCode::InvalidData, "length_mismatch",
         "array lengths disagree with M = " + std::to_string(m) + ": " + std::to_string(g.means.size()) +
             " mean values, " + std::to_string(g.covariances.size()) + " covariance values");
  }
  check_strings(model, ErrorCode::InvalidData);
  if (model.pose) check_pose(*model.pose);
  check_values(g);
}

struct EncodedArray {
  ArrayRecord record;
  std::vector<std::uint8_t> stored;
};

EncodedArray encode_one(const std::vector<float>& values, std::uint64_t cols, const WriteOptions& options) {
  EncodedArray out;
  const bool f64 = options.float64;
  const std::vector<std::uint8_t> canonical = canonical_bytes(values, f64);
  const Shape shape{values.size() / cols, cols, f64 ? 8u : 4u};
  out.record.dtype = f64 ? kDTypeF64 : kDTypeF32;
  out.record.decoded_length = canonical.size();
  out.record.crc32c = crc32c(canonical.data(), canonical.size());
  out.stored = canonical;  // raw: component-major, no filter, no codec
  if (options.compress) {
    const Encoding packed{kOrderColumnMajor, kFilterByteStreamSplit, kCodecZstd};
    std::vector<std::uint8_t> z = encode_array(canonical, shape, packed, options.zstd_level);
    if (z.size() < out.stored.size()) {
      out.stored = std::move(z);
      out.record.order = packed.order;
      out.record.filter = packed.filter;
      out.record.codec = packed.codec;
    }
  }
  out.record.stored_length = out.stored.size();
  return out;
}

}  // namespace

std::vector<std::uint8_t> encode(const Model& model, const WriteOptions& options, const Tweaks& t) {
  if (t.validate) validate_for_write(model);
  const Gmm& g = model.gmm;
  const std::size_t m = g.weights.size();
  const bool packed = !t.force_full_layout && g.covariances.size() == 16 * m && bit_symmetric(g.covariances, m);

  EncodedArray arrays[3] = {
      encode_one(g.weights, 1, options),
      encode_one(g.means, 4, options),
      encode_one(packed ? pack_upper(g.covariances, m) : g.covariances, packed ? 10 : 16, options),
  };
  const std::uint64_t n_declared = t.n_components ? *t.n_components : m;
  if (t.lengths_follow_declared_m) {
    for (int i = 0; i < 3; ++i) {
      arrays[i].record.decoded_length = n_declared * columns(i, packed) * (options.float64 ? 8 : 4);
    }
  }
  arrays[kCovariances].record.crc32c ^= t.covariance_crc_xor;
  if (t.means_codec) arrays[kMeans].record.codec = *t.means_codec;

  // Offsets depend on the metadata length and vice versa: every offset field
  // is always present (non-zero), so the length is fixed after one pass.
  ArrayRecord records[3];
  std::vector<std::uint8_t> metadata;
  std::uint64_t placeholder_length = 0;
  for (int pass = 0; pass < 4; ++pass) {
    std::uint64_t offset = kHeaderSize + pad8(pass == 0 ? 0 : metadata.size());
    for (int i = 0; i < 3; ++i) {
      records[i] = arrays[i].record;
      records[i].offset = pass == 0 ? (std::uint64_t{1} << 40) : offset;
      offset = pad8(offset + arrays[i].stored.size());
    }
    if (t.means_offset) records[kMeans].offset = *t.means_offset;
    metadata = build_metadata(model, records, n_declared, packed, t);
    if (pass > 0 && metadata.size() == placeholder_length) break;
    placeholder_length = metadata.size();
  }

  Header h;
  h.major = t.major;
  h.minor = t.minor;
  h.metadata_length = static_cast<std::uint32_t>(metadata.size());
  h.metadata_crc32c = crc32c(metadata.data(), metadata.size());
  // Arrays follow the metadata, each at a multiple of 8; no padding after the last.
  std::uint64_t body_end = kHeaderSize + pad8(metadata.size());
  for (int i = 0; i < 3; ++i) {
    body_end += arrays[i].stored.size();
    if (i < 2) body_end = pad8(body_end);
  }
  h.file_length = body_end + kTrailerSize;

  std::vector<std::uint8_t> file(h.file_length, 0);
  write_header(file.data(), h);
  std::memcpy(&file[kHeaderSize], metadata.data(), metadata.size());
  std::uint64_t offset = kHeaderSize + pad8(metadata.size());
  for (int i = 0; i < 3; ++i) {
    if (!arrays[i].stored.empty()) std::memcpy(&file[offset], arrays[i].stored.data(), arrays[i].stored.size());
    offset = pad8(offset + arrays[i].stored.size());
  }
  std::memcpy(&file[h.file_length - kTrailerSize], kEndMagic.data(), kEndMagic.size());
  return file;
}

void refresh_metadata_crc(std::vector<std::uint8_t>& file) {
  const std::uint32_t len = load_le<std::uint32_t>(&file[24]);
  store_le<std::uint32_t>(&file[28], crc32c(&file[kHeaderSize], len));
}

}  // namespace detail

std::vector<std::uint8_t> to_bytes(const Model& model, const WriteOptions& options) {
  return detail::encode(model, options, detail::Tweaks{});
}

void save(const std::string& path, const Model& model, const WriteOptions& options) {
  detail::atomic_write(path, to_bytes(model, options));
}

}  // namespace sogmm::format
