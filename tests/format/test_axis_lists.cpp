// Format 1.5 (spec/format.md section 7): a file with feature bit 2 or 3
// leaves out the fixed axis lists. Checked against the same model written as
// formats 1.3 / 1.4 wrote it (Tweaks::axis_lists): the reader returns the same
// model and the same dump but the file's version, lengths and offsets; files
// without those bits keep the lists and their version.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "internal.hpp"
#include "sogmm/format.hpp"
#include "sogmm_generated.h"
#include "test_support.hpp"

namespace sogmm::format {
namespace {

// Frame lines the record gives back byte for byte (spec/format.md 2.3.2).
constexpr const char* kFrames = "0 10 10 1 0 0 0.5 0 1 0 -0.25 0 0 1 2 4\n1 12 3 1 0 0 0.75 0 1 0 -0.25 0 0 1 2 6\n";

Model map_model() {
  Model m = test::synthetic_model(6, 3);
  m.key_values = {{"coordinate_frame", "world"}, {"map_frames", kFrames}, {"map_options", "novelty=1"}};
  return m;
}

bool has_axis_lists(const std::vector<std::uint8_t>& file) {
  const fb::SogmmFile* root = fb::GetSogmmFile(file.data() + 32);
  return root->axis_labels() != nullptr || root->axis_units() != nullptr;
}

// The dump without its "file" member (version, lengths, offsets).
std::string content_dump(const std::vector<std::uint8_t>& file) {
  const Model m = from_bytes(file.data(), file.size());
  const std::string dump = to_canonical_json(m);
  EXPECT_EQ(dump.find("\"file\""), std::string::npos);
  return dump;
}

TEST(AxisLists, FilesWithBit2Or3LeaveThemOutAndReadTheSame) {
  WriteOptions quantized;
  quantized.component_precision = 0.5;
  const struct {
    Model model;
    WriteOptions options;
    std::uint64_t features;
    std::uint16_t old_minor;
  } cases[] = {{map_model(), {}, 0xA, 3}, {map_model(), quantized, 0xE, 4}, {test::synthetic_model(6, 4), quantized, 0x4, 4}};
  for (const auto& c : cases) {
    const std::vector<std::uint8_t> now = to_bytes(c.model, c.options);
    detail::Tweaks old_form;
    old_form.axis_lists = true;
    const std::vector<std::uint8_t> before = detail::encode(c.model, c.options, old_form);
    const FileInfo info_now = read_info(now.data(), now.size());
    const FileInfo info_before = read_info(before.data(), before.size());
    ASSERT_EQ(info_now.features_required, c.features);
    EXPECT_EQ(info_before.features_required, c.features);
    EXPECT_EQ(info_now.format_minor, 5u);
    EXPECT_EQ(info_before.format_minor, c.old_minor);
    EXPECT_FALSE(has_axis_lists(now));
    EXPECT_TRUE(has_axis_lists(before));
    // The labels (a 4-byte length, 4 offsets, "x" "y" "z" in 8 bytes each and
    // "gray" in 12: 56), the units (20 + 4 x 8: 52) and their two offsets in
    // the root table (8): 116 bytes, 120 in a block whose length is a multiple of 8.
    EXPECT_EQ(info_before.metadata_length - info_now.metadata_length, 120u);
    EXPECT_EQ(before.size() - now.size(), 120u);
    const Model a = from_bytes(now.data(), now.size());
    const Model b = from_bytes(before.data(), before.size());
    EXPECT_TRUE(test::bit_equal(a, b));
    EXPECT_EQ(a.key_values, c.model.key_values);
    EXPECT_EQ(content_dump(now), content_dump(before));
  }
}

TEST(AxisLists, FilesWithoutThoseBitsKeepThemAndTheirVersion) {
  const Model plain = test::synthetic_model(6, 5);
  const std::vector<std::uint8_t> file = to_bytes(plain);
  EXPECT_TRUE(has_axis_lists(file));
  EXPECT_EQ(read_info(file.data(), file.size()).format_minor, 0u);
  // A map delta (bits 0 and 1) too.
  const std::vector<std::uint8_t> delta = detail::encode(map_model(), {}, detail::map_delta_tweaks());
  EXPECT_TRUE(has_axis_lists(delta));
}

}  // namespace
}  // namespace sogmm::format
