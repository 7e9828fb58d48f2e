// The writer keeps to the reader's decoded-size cap (spec/format.md section
// 8): a model whose arrays decode to more bytes than the cap (by default the
// reader's 1 GiB) is refused with Error(Limit) before anything is written,
// and the writer's arithmetic is the reader's: for small caps around a
// model's exact size, to_bytes succeeds exactly when from_bytes with the same
// cap does. The 1 GiB boundary itself is tested on the size check (a model
// there would need ~1.5 GB of memory).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "schema.hpp"
#include "sogmm/format.hpp"
#include "sogmm/sogmm.h"
#include "test_support.hpp"

namespace {

using sogmm::format::FormatError;
using sogmm::format::kDefaultMaxDecodedBytes;
using sogmm::format::detail::check_decoded_size;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The message of check_decoded_size, or "" when it accepts.
std::string refusal(std::uint64_t m, bool packed, bool f64, std::uint64_t cap = kDefaultMaxDecodedBytes) {
  try {
    check_decoded_size(m, packed, f64, cap);
  } catch (const FormatError& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit);
    EXPECT_EQ(e.reason(), "limit");
    return e.what();
  }
  return "";
}

TEST(WriteCap, DefaultCapBoundaryIsTheReaders) {
  // Bytes per component: (1 + 4 + 10) values packed, (1 + 4 + 16) full; 4 or 8 bytes each.
  struct Case { bool packed, f64; std::uint64_t per; };
  for (const Case c : {Case{true, false, 60}, Case{true, true, 120}, Case{false, false, 84}, Case{false, true, 168}}) {
    const std::uint64_t m_max = kDefaultMaxDecodedBytes / c.per;  // the largest M a default reader accepts
    EXPECT_EQ(refusal(m_max, c.packed, c.f64), "") << c.per;
    const std::string msg = refusal(m_max + 1, c.packed, c.f64);
    ASSERT_FALSE(msg.empty()) << c.per;
    EXPECT_TRUE(has(msg, std::to_string((m_max + 1) * c.per) + " bytes")) << msg;
    EXPECT_TRUE(has(msg, "1 GiB (1073741824 bytes)")) << msg;
    EXPECT_TRUE(has(msg, "SOGMM_OPT_MAX_DECODED_BYTES")) << msg;
  }
  EXPECT_EQ(kDefaultMaxDecodedBytes / 60, 17895697u);  // "about 17.9 million float32 components"
  // Overflow of the byte count is refused, not wrapped.
  EXPECT_TRUE(has(refusal(UINT64_MAX / 4, true, true, UINT64_MAX), "more than 2^64"));
  EXPECT_TRUE(has(refusal(100, true, false, 100), "the cap of 100 bytes given for writing"));
}

// Sum of the arrays' declared decoded lengths, read back from a file.
std::uint64_t declared_bytes(const std::vector<std::uint8_t>& file) {
  const sogmm::format::FileInfo info = sogmm::format::read_info(file.data(), file.size());
  return info.weights.decoded_length + info.means.decoded_length + info.covariances.decoded_length;
}

TEST(WriteCap, WriterAcceptsExactlyWhatTheReaderWithTheSameCapAccepts) {
  for (std::size_t m : {1u, 2u, 7u}) {
    for (bool f64 : {false, true}) {
      for (bool full : {false, true}) {
        sogmm::Model model = sogmm::test::synthetic_model(m, 11, false);
        if (full) model.gmm.covariances[1] = std::nextafter(model.gmm.covariances[1], 1.0f);  // not bit-symmetric
        sogmm::format::WriteOptions w;
        w.float64 = f64;
        const std::vector<std::uint8_t> file = sogmm::format::to_bytes(model, w);
        const std::uint64_t need = declared_bytes(file);
        EXPECT_EQ(need, m * (full ? 21u : 15u) * (f64 ? 8u : 4u));
        for (std::uint64_t cap : {need - 1, need}) {
          w.max_decoded_bytes = cap;
          sogmm::format::ReadOptions r;
          r.max_decoded_bytes = cap;
          bool wrote = true, read = true;
          try {
            sogmm::format::to_bytes(model, w);
          } catch (const FormatError& e) {
            EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit) << e.what();
            wrote = false;
          }
          try {
            sogmm::format::from_bytes(file.data(), file.size(), r);
          } catch (const FormatError& e) {
            EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit) << e.what();
            read = false;
          }
          EXPECT_EQ(wrote, cap == need) << "m " << m << " f64 " << f64 << " full " << full;
          EXPECT_EQ(wrote, read) << "m " << m << " f64 " << f64 << " full " << full << " cap " << cap;
        }
      }
    }
  }
}

TEST(WriteCap, CapiSaveRefusesAboveTheCapAndKeepsThePreviousFile) {
  const sogmm::Gmm g = sogmm::test::synthetic_model(2, 5, false).gmm;  // symmetric: packed covariances
  sogmm_model* m = nullptr;
  ASSERT_EQ(sogmm_model_from_arrays_f32(&m, 2, g.weights.data(), g.means.data(), g.covariances.data(), 100), SOGMM_OK);
  const std::string dir = sogmm::test::make_scratch_dir("write-cap");
  const std::string path = dir + "/m.sogmm";
  ASSERT_EQ(sogmm_model_save(m, path.c_str(), nullptr), SOGMM_OK) << sogmm_last_error();
  const std::vector<std::uint8_t> before = sogmm::test::read_file_bytes(path);

  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  const std::int64_t need = 2 * 15 * 4;  // packed float32
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, need - 1), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_ZSTD_LEVEL, 3), SOGMM_OK);  // another file, were it written
  EXPECT_EQ(sogmm_model_save(m, path.c_str(), o), SOGMM_E_LIMIT);
  EXPECT_TRUE(has(sogmm_last_error(), "would decode to 120 bytes, over the cap of 119 bytes")) << sogmm_last_error();
  EXPECT_EQ(sogmm::test::read_file_bytes(path), before);
  EXPECT_EQ(sogmm::test::list_dir(dir).size(), 1u);  // no temporary file left
  sogmm_buffer* buf = reinterpret_cast<sogmm_buffer*>(1);
  EXPECT_EQ(sogmm_model_save_to_memory(&buf, m, o), SOGMM_E_LIMIT);
  EXPECT_EQ(buf, nullptr);

  // The same cap on both sides: written and read back.
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, need), SOGMM_OK);
  ASSERT_EQ(sogmm_model_save(m, path.c_str(), o), SOGMM_OK) << sogmm_last_error();
  sogmm_model* back = nullptr;
  EXPECT_EQ(sogmm_model_load(&back, path.c_str(), o), SOGMM_OK) << sogmm_last_error();
  sogmm_model_free(back);
  sogmm_options_free(o);
  sogmm_model_free(m);
  sogmm::test::remove_scratch_dir(dir);
}

}  // namespace
