// The bytes of a file checked against the spec by hand: header fields,
// checksums computed independently, raw array bytes, byte-stream split.
#include <gtest/gtest.h>
#include <zstd.h>

#include <cstring>

#include "crc32c.hpp"
#include "sogmm/format.hpp"
#include "test_support.hpp"

namespace sogmm {
namespace {

using test::le;

TEST(Crc32c, KnownValues) {
  const char* s = "123456789";
  EXPECT_EQ(format::detail::crc32c(s, 9), 0xE3069283u);  // the standard check value
  std::vector<std::uint8_t> zeros(32, 0), ones(32, 0xFF);
  EXPECT_EQ(format::detail::crc32c(zeros.data(), 32), 0x8A9136AAu);  // RFC 3720 B.4
  EXPECT_EQ(format::detail::crc32c(ones.data(), 32), 0x62A8AB43u);
  std::vector<std::uint8_t> inc(32);
  for (int i = 0; i < 32; ++i) inc[i] = static_cast<std::uint8_t>(i);
  EXPECT_EQ(format::detail::crc32c(inc.data(), 32), 0x46DD794Eu);
}

TEST(Crc32c, MatchesBitwiseOnAllLengthsAndChaining) {
  std::vector<std::uint8_t> d(300);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = static_cast<std::uint8_t>(i * 131 + 7);
  for (std::size_t n = 0; n <= d.size(); n += 7) {
    EXPECT_EQ(format::detail::crc32c(d.data(), n), test::crc32c_bitwise(d.data(), n)) << n;
  }
  const std::uint32_t part = format::detail::crc32c(d.data(), 100);
  EXPECT_EQ(format::detail::crc32c(d.data() + 100, 200, part), test::crc32c_bitwise(d.data(), 300));
}

// An uncompressed file, decoded by hand from the spec's byte layout.
TEST(Layout, UncompressedFileMatchesSpecByteForByte) {
  const Model model = test::synthetic_model(3, 7);
  format::WriteOptions opts;
  opts.compress = false;
  const std::vector<std::uint8_t> f = format::to_bytes(model, opts);
  const std::uint8_t magic[8] = {0x89, 'S', 'O', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  ASSERT_GE(f.size(), 36u);
  EXPECT_EQ(std::memcmp(f.data(), magic, 8), 0);
  EXPECT_EQ(le<std::uint16_t>(f, 8), 1);  // major
  EXPECT_EQ(le<std::uint16_t>(f, 10), 0);  // minor
  EXPECT_EQ(le<std::uint32_t>(f, 12), 0u);  // flags
  EXPECT_EQ(le<std::uint64_t>(f, 16), f.size());
  const std::uint32_t meta_len = le<std::uint32_t>(f, 24);
  EXPECT_EQ(le<std::uint32_t>(f, 28), test::crc32c_bitwise(f.data() + 32, meta_len));
  EXPECT_EQ(std::memcmp(f.data() + f.size() - 4, "SGMM", 4), 0);
  EXPECT_EQ(std::memcmp(f.data() + 32 + 4, "SGMM", 4), 0);  // FlatBuffers file identifier

  // The body: weights, means, packed covariances, raw float32 LE, 8-aligned.
  std::size_t off = 32 + ((meta_len + 7) / 8) * 8;
  auto expect_floats = [&](const std::vector<float>& values) {
    ASSERT_LE(off + 4 * values.size(), f.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      std::uint32_t bits;
      std::memcpy(&bits, &values[i], 4);
      ASSERT_EQ(le<std::uint32_t>(f, off + 4 * i), bits) << "value " << i;
    }
    off = ((off + 4 * values.size() + 7) / 8) * 8;
  };
  expect_floats(model.gmm.weights);
  expect_floats(model.gmm.means);
  std::vector<float> packed;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) packed.push_back(model.gmm.covariances[16 * k + 4 * i + j]);
  const std::size_t cov_off = off;
  expect_floats(packed);
  EXPECT_EQ(cov_off + 4 * packed.size() + 4, f.size());  // then only the trailer

  const format::FileInfo info = format::read_info(f.data(), f.size());
  EXPECT_EQ(info.covariances.offset, cov_off);
  EXPECT_EQ(info.covariances.codec, "none");
  EXPECT_EQ(info.covariance_layout, "upper_packed");
  std::vector<std::uint8_t> raw(f.begin() + static_cast<long>(cov_off), f.begin() + static_cast<long>(cov_off + 120));
  EXPECT_EQ(info.covariances.crc32c, test::crc32c_bitwise(raw.data(), raw.size()));
}

// A compressed array decoded by hand: zstd frames, one per byte stream, of
// the column-major elements.
TEST(Layout, ByteStreamSplitDecodesByHand) {
  const Model model = test::synthetic_model(50, 11);
  const std::vector<std::uint8_t> f = format::to_bytes(model);
  const format::FileInfo info = format::read_info(f.data(), f.size());
  const format::ArrayInfo& a = info.means;
  ASSERT_EQ(a.codec, "zstd");
  ASSERT_EQ(a.filter, "byte_stream_split");
  ASSERT_EQ(a.order, "column_major");
  std::vector<std::uint8_t> decoded;
  std::size_t in = a.offset;
  const std::size_t end = a.offset + a.stored_length;
  while (in < end) {
    const std::size_t fs = ZSTD_findFrameCompressedSize(&f[in], end - in);
    ASSERT_FALSE(ZSTD_isError(fs));
    const unsigned long long cs = ZSTD_getFrameContentSize(&f[in], fs);
    ASSERT_EQ(cs, 200u);  // one stream: one byte of each of the 50 x 4 elements
    std::vector<std::uint8_t> out(cs);
    ASSERT_EQ(ZSTD_decompress(out.data(), out.size(), &f[in], fs), cs);
    decoded.insert(decoded.end(), out.begin(), out.end());
    in += fs;
  }
  ASSERT_EQ(decoded.size(), 800u);
  for (int k = 0; k < 50; ++k) {
    for (int c = 0; c < 4; ++c) {
      const std::size_t e = static_cast<std::size_t>(c) * 50 + static_cast<std::size_t>(k);  // column-major index
      std::uint32_t bits = 0;
      for (int b = 0; b < 4; ++b) bits |= std::uint32_t{decoded[b * 200 + e]} << (8 * b);
      std::uint32_t want;
      std::memcpy(&want, &model.gmm.means[4 * k + c], 4);
      ASSERT_EQ(bits, want) << k << "," << c;
    }
  }
}

}  // namespace
}  // namespace sogmm
