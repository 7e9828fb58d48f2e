// Models round-trip bit-exactly through bytes and files, in every encoding.
#include <gtest/gtest.h>

#include <cmath>

#include "sogmm/format.hpp"
#include "test_support.hpp"

namespace sogmm {
namespace {

struct Case {
  std::size_t m;
  bool compress;
  bool f64;
  bool full_metadata;
};

class RoundTrip : public ::testing::TestWithParam<Case> {};

TEST_P(RoundTrip, BitExact) {
  const Case c = GetParam();
  const Model model = test::synthetic_model(c.m, static_cast<std::uint32_t>(c.m * 3 + 1), c.full_metadata);
  format::WriteOptions opts;
  opts.compress = c.compress;
  opts.float64 = c.f64;
  const std::vector<std::uint8_t> bytes = format::to_bytes(model, opts);
  const Model back = format::from_bytes(bytes.data(), bytes.size());
  Model expected = model;
  if (expected.producer_version.empty()) expected.producer_version = sogmm::version_string();
  EXPECT_TRUE(test::bit_equal(back, expected));
  // Re-encoding the decoded model gives the same bytes (deterministic writer).
  EXPECT_EQ(format::to_bytes(back, opts), bytes);
  const format::FileInfo info = format::read_info(bytes.data(), bytes.size());
  EXPECT_EQ(info.n_components, c.m);
  EXPECT_EQ(info.weights.dtype, c.f64 ? "f64" : "f32");
  EXPECT_EQ(info.covariance_layout, "upper_packed");
}

INSTANTIATE_TEST_SUITE_P(Encodings, RoundTrip,
                         ::testing::Values(Case{1, true, false, true}, Case{1, false, false, false},
                                           Case{2, true, true, true}, Case{64, true, false, true},
                                           Case{64, false, true, false}, Case{500, true, false, true},
                                           Case{500, true, true, true}, Case{3, true, false, false}));

TEST(RoundTrip, SlightlyAsymmetricCovarianceIsStoredFullAndReadAsItsSymmetricPart) {
  Model model = test::synthetic_model(5, 3);
  float& upper = model.gmm.covariances[16 * 2 + 1];
  const float lower = model.gmm.covariances[16 * 2 + 4];
  ASSERT_EQ(upper, lower);
  upper = std::nextafter(upper, 1.0f);  // within the symmetry tolerance, but not bit-symmetric
  const std::vector<std::uint8_t> bytes = format::to_bytes(model);
  EXPECT_EQ(format::read_info(bytes.data(), bytes.size()).covariance_layout, "full");  // the file keeps it
  // spec/format.md 5.1: the reader returns (a01 + a10) / 2 rounded to float32.
  Model expected = model;
  expected.gmm.covariances[16 * 2 + 1] = expected.gmm.covariances[16 * 2 + 4] = test::symmetric_tie(lower, upper);
  EXPECT_TRUE(test::bit_equal(format::from_bytes(bytes.data(), bytes.size()), expected));
}

TEST(RoundTrip, SpecialButValidValues) {
  Model model = test::synthetic_model(4, 5, false);
  model.gmm.means[0] = -0.0f;                       // negative zero survives
  model.gmm.means[5] = std::numeric_limits<float>::denorm_min();
  for (int i = 0; i < 4; ++i)  // component 1: diagonal covariance with signed zeros
    for (int j = 0; j < 4; ++j)
      if (i != j) model.gmm.covariances[16 + 4 * i + j] = -0.0f;
  model.producer_name = "";
  model.gmm.support_size = ~std::uint64_t{0};
  model.created_unix_ms = -5;
  const std::vector<std::uint8_t> bytes = format::to_bytes(model);
  const Model back = format::from_bytes(bytes.data(), bytes.size());
  Model expected = model;
  expected.producer_version = sogmm::version_string();
  EXPECT_TRUE(test::bit_equal(back, expected));
  EXPECT_TRUE(std::signbit(back.gmm.means[0]));
}

TEST(RoundTrip, MetadataOnlyReadDoesNotNeedTheBody) {
  const Model model = test::synthetic_model(20, 9);
  std::vector<std::uint8_t> bytes = format::to_bytes(model);
  const format::FileInfo info = format::read_info(bytes.data(), bytes.size());
  // Destroy the body: read_info still succeeds, from_bytes does not.
  for (std::uint64_t i = info.weights.offset; i < bytes.size() - 4; ++i) bytes[i] = 0xAB;
  const format::FileInfo again = format::read_info(bytes.data(), bytes.size());
  EXPECT_EQ(again.metadata.producer_name, "sogmm-tests");
  EXPECT_EQ(again.metadata.gmm.support_size, model.gmm.support_size);
  EXPECT_TRUE(again.metadata.pose.has_value());
  EXPECT_EQ(again.metadata.key_values, model.key_values);
  EXPECT_THROW(format::from_bytes(bytes.data(), bytes.size()), format::FormatError);
}

TEST(RoundTrip, CompressionBeatsThePapersSixtyBytesPerComponent) {
  const Model model = test::synthetic_model(500, 21);
  const std::vector<std::uint8_t> bytes = format::to_bytes(model);
  const double per_component = static_cast<double>(bytes.size()) / 500.0;
  RecordProperty("bytes_per_component", std::to_string(per_component));
  EXPECT_LT(per_component, 60.0);
}

TEST(CanonicalJson, HasTheDocumentedShape) {
  const Model model = test::synthetic_model(2, 1);
  const std::vector<std::uint8_t> bytes = format::to_bytes(model);
  const format::FileInfo info = format::read_info(bytes.data(), bytes.size());
  const std::string j = format::to_canonical_json(format::from_bytes(bytes.data(), bytes.size()), &info);
  for (const char* key : {"\"file\"", "\"format_version\": \"1.0\"", "\"n_components\": 2", "\"weights\"",
                          "\"covariances\"", "\"key_values\"", "\"pose\"", "\"camera\"", "\"fit\""}) {
    EXPECT_NE(j.find(key), std::string::npos) << key;
  }
  EXPECT_LT(j.find("\"file\""), j.find("\"n_components\""));
}

}  // namespace
}  // namespace sogmm
