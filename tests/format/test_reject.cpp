// Bad input is rejected with the documented code and reason, never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "internal.hpp"
#include "sogmm/format.hpp"
#include "test_support.hpp"

namespace sogmm {
namespace {

using format::FormatError;

// Runs f, expecting a FormatError with this code and reason.
template <typename F>
void expect_rejected(F&& f, ErrorCode code, const std::string& reason) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected " << reason;
  } catch (const FormatError& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_EQ(e.reason(), reason) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(reason + ": ", 0), 0u) << e.what();
  }
}

void expect_read_rejected(const std::vector<std::uint8_t>& b, ErrorCode code, const std::string& reason,
                          const format::ReadOptions& o = {}) {
  expect_rejected([&] { format::from_bytes(b.data(), b.size(), o); }, code, reason);
}

std::vector<std::uint8_t> good(std::size_t m = 10, bool compress = true) {
  format::WriteOptions o;
  o.compress = compress;
  return format::to_bytes(test::synthetic_model(m, 5), o);
}

TEST(Reject, BadMagicAndTextModeMangling) {
  std::vector<std::uint8_t> b = good();
  b[1] = 'X';
  expect_read_rejected(b, ErrorCode::Format, "bad_magic");
  // What a text-mode transfer does: CR LF -> LF.
  std::vector<std::uint8_t> t = good();
  t.erase(t.begin() + 4);
  expect_read_rejected(t, ErrorCode::Format, "bad_magic");
  // High bit stripped by a 7-bit channel.
  std::vector<std::uint8_t> s = good();
  s[0] = 0x09;
  expect_read_rejected(s, ErrorCode::Format, "bad_magic");
  const char text[] = "{\"not\": \"a model\"}";
  expect_rejected([&] { format::from_bytes(text, sizeof text); }, ErrorCode::Format, "bad_magic");
}

TEST(Reject, EveryTruncationIsRejected) {
  const std::vector<std::uint8_t> b = good(4);
  for (std::size_t n = 0; n < b.size(); ++n) {
    try {
      format::from_bytes(b.data(), n);
      ADD_FAILURE() << "truncation to " << n << " bytes accepted";
    } catch (const FormatError& e) {
      // Truncation is detected by the size checks, except that a cut file's
      // last 4 bytes are no longer the trailer only after the length check.
      EXPECT_EQ(e.code(), ErrorCode::Format);
      EXPECT_EQ(e.reason(), "truncated") << "n = " << n << ": " << e.what();
    }
  }
  // Read with a null pointer and size 0.
  expect_rejected([&] { format::from_bytes(nullptr, 0); }, ErrorCode::Format, "truncated");
}

TEST(Reject, HeaderFields) {
  std::vector<std::uint8_t> b = good();
  b[8] = 2;  // major 2
  expect_read_rejected(b, ErrorCode::Format, "unsupported_version");
  b = good();
  b[10] = 7;  // minor 7: accepted (no unknown required feature)
  EXPECT_NO_THROW(format::from_bytes(b.data(), b.size()));
  b = good();
  b[13] = 1;  // flags
  expect_read_rejected(b, ErrorCode::Format, "bad_header");
  b = good();
  b.insert(b.end(), {0, 0, 0, 0});  // trailing data
  expect_read_rejected(b, ErrorCode::Format, "bad_header");
  b = good();
  b[b.size() - 1] = 'X';
  expect_read_rejected(b, ErrorCode::Format, "bad_trailer");
  b = good();
  b[24] = 0xFF, b[25] = 0xFF, b[26] = 0xFF;  // metadata length beyond the file
  expect_read_rejected(b, ErrorCode::Format, "bad_header");
}

TEST(Reject, Checksums) {
  std::vector<std::uint8_t> b = good();
  b[32 + 20] ^= 0x01;  // inside the metadata
  expect_read_rejected(b, ErrorCode::Format, "checksum_mismatch");
  format::detail::Tweaks t;
  t.covariance_crc_xor = 1;
  const Model m = test::synthetic_model(6, 2);
  b = format::detail::encode(m, {}, t);
  expect_read_rejected(b, ErrorCode::Format, "checksum_mismatch");
  format::ReadOptions no_check;
  no_check.verify_checksums = false;
  EXPECT_TRUE(test::bit_equal(format::from_bytes(b.data(), b.size(), no_check), m));
  // A flipped bit in raw (uncompressed) array data.
  b = good(10, false);
  const format::FileInfo info = format::read_info(b.data(), b.size());
  b[info.means.offset + 3] ^= 0x10;
  expect_read_rejected(b, ErrorCode::Format, "checksum_mismatch");
}

TEST(Reject, MetadataThatFailsVerification) {
  std::vector<std::uint8_t> b = good();
  b[32] = 0xF0, b[33] = 0xFF, b[34] = 0x00, b[35] = 0x00;  // root offset far outside the buffer
  format::detail::refresh_metadata_crc(b);
  expect_read_rejected(b, ErrorCode::Format, "bad_metadata");
  b = good();
  b[36] = 'X';  // FlatBuffers file identifier
  format::detail::refresh_metadata_crc(b);
  expect_read_rejected(b, ErrorCode::Format, "bad_metadata");
}

TEST(Reject, FeaturesEncodingsAndMetadataValues) {
  const Model m = test::synthetic_model(6, 2);
  format::detail::Tweaks t;
  t.features_required = 1u << 4;  // bits 0-3 are assigned (spec/format.md section 7); 4 is not
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "unsupported_feature");
  t = {};
  t.features_used = 1u << 3;  // optional features are ignored
  t.minor = 9;
  t.unknown_optional_fields = true;
  const auto future = format::detail::encode(m, {}, t);
  EXPECT_TRUE(test::bit_equal(format::from_bytes(future.data(), future.size()), m));
  t = {};
  t.means_codec = 9;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "unsupported_encoding");
  t = {};
  t.dims = 3;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "bad_metadata");
  t = {};
  t.axis_units = std::vector<std::string>{"mm", "mm", "mm", "1"};
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "bad_metadata");
  t = {};
  t.raw_pose = std::vector<double>(12, 0.0);
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "bad_metadata");
  t = {};
  t.means_offset = 41;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "bad_layout");
  t.means_offset = 1u << 20;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Format, "bad_layout");
}

TEST(Reject, CountsLengthsAndTheSizeCap) {
  const Model m = test::synthetic_model(6, 2);
  format::detail::Tweaks t;
  t.n_components = 0;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::InvalidData, "empty");
  t.n_components = 7;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::InvalidData, "length_mismatch");
  t.n_components = std::uint64_t{1} << 62;  // M * C * 4 overflows 64 bits
  t.lengths_follow_declared_m = true;
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::InvalidData, "length_mismatch");
  t.n_components = std::uint64_t{1} << 26;  // 4 GiB declared: over the default cap, nothing allocated
  expect_read_rejected(format::detail::encode(m, {}, t), ErrorCode::Limit, "limit");
  format::ReadOptions small;
  small.max_decoded_bytes = 6 * 15 * 4 - 1;
  expect_read_rejected(good(6), ErrorCode::Limit, "limit", small);
  small.max_decoded_bytes = 6 * 15 * 4;
  const auto exact = format::to_bytes(m);
  EXPECT_NO_THROW(format::from_bytes(exact.data(), exact.size(), small));
}

TEST(Reject, ValuesOnReadAndOnWrite) {
  format::detail::Tweaks no_validate;
  no_validate.validate = false;
  struct Bad {
    const char* reason;
    ErrorCode code;
    void (*mutate)(Model&);
  };
  const Bad cases[] = {
      {"non_finite", ErrorCode::Numeric, [](Model& m) { m.gmm.means[5] = std::numeric_limits<float>::quiet_NaN(); }},
      {"non_finite", ErrorCode::Numeric, [](Model& m) { m.gmm.covariances[0] = std::numeric_limits<float>::infinity(); }},
      {"bad_weights", ErrorCode::Numeric, [](Model& m) { m.gmm.weights[0] += 0.01f; }},
      {"bad_weights", ErrorCode::Numeric,
       [](Model& m) {
         m.gmm.weights[1] += m.gmm.weights[0] + 0.25f;
         m.gmm.weights[0] = -0.25f;
       }},
      {"not_spd", ErrorCode::Numeric,
       [](Model& m) {
         for (int i = 0; i < 4; ++i) m.gmm.covariances[16 * 2 + 5 * i] *= -1.0f;
       }},
      {"not_symmetric", ErrorCode::Numeric, [](Model& m) { m.gmm.covariances[16 * 3 + 1] += 0.01f; }},
      {"empty", ErrorCode::InvalidData, [](Model& m) { m.gmm.resize(0); }},
      {"bad_pose", ErrorCode::InvalidData, [](Model& m) { (*m.pose)[0] = 2.0; }},
      {"bad_pose", ErrorCode::InvalidData, [](Model& m) { (*m.pose)[15] = 0.5; }},
  };
  for (const Bad& c : cases) {
    SCOPED_TRACE(c.reason);
    Model m = test::synthetic_model(6, 2);
    c.mutate(m);
    expect_rejected([&] { format::to_bytes(m); }, c.code, c.reason);
    if (std::string(c.reason) == "empty") continue;  // an empty file is covered by the tweak test above
    const auto bytes = format::detail::encode(m, {}, no_validate);
    expect_read_rejected(bytes, c.code, c.reason);
  }
  Model m = test::synthetic_model(6, 2);
  m.gmm.means.pop_back();
  expect_rejected([&] { format::to_bytes(m); }, ErrorCode::InvalidData, "length_mismatch");
}

TEST(Reject, F64ValuesThatOverflowFloat32) {
  // A float64 file whose weight-free values are fine in double but not in float32.
  Model m = test::synthetic_model(2, 2, false);
  const auto bytes = format::detail::encode(m, format::WriteOptions{19, true, false}, {});
  std::vector<std::uint8_t> b = bytes;
  const format::FileInfo info = format::read_info(b.data(), b.size());
  const double big = 1e300;
  std::memcpy(&b[info.means.offset], &big, 8);  // raw f64, component-major: mean x of component 0
  format::ReadOptions no_check;
  no_check.verify_checksums = false;
  expect_read_rejected(b, ErrorCode::Numeric, "non_finite", no_check);
}

// Every single-byte corruption is either rejected with a sogmm::Error or
// (only in unchecked padding) decodes to the very same model.
TEST(Reject, EverySingleByteCorruptionIsCaughtOrHarmless) {
  for (bool compress : {true, false}) {
    const Model m = test::synthetic_model(5, 4);
    const std::vector<std::uint8_t> b = format::to_bytes(m, format::WriteOptions{19, false, compress});
    for (std::size_t i = 0; i < b.size(); ++i) {
      for (std::uint8_t x : {0x01, 0x80, 0xFF}) {
        std::vector<std::uint8_t> c = b;
        c[i] ^= x;
        try {
          const Model back = format::from_bytes(c.data(), c.size());
          EXPECT_TRUE(test::bit_equal(back, m)) << "byte " << i << " accepted with a different model";
        } catch (const Error&) {
        }
      }
    }
  }
}

}  // namespace
}  // namespace sogmm
