// Map deltas in the container (sogmm/map_delta_file.hpp, spec/format.md
// section 2.5): bit-exact round trip, and the two readers keep apart.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include "sogmm/format.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

#include "internal.hpp"

namespace {

// A textured wall of n x n points at z = 1.5 m (no randomness needed: the
// delta only has to carry what the map fitted).
std::vector<float> wall(int n, double shift) {
  std::vector<float> p;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = shift + 0.6 * i / n - 0.3, y = 0.6 * j / n - 0.3;
      const double z = 1.5 + 0.002 * std::sin(37.0 * x + 11.0 * y);
      p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                         static_cast<float>(0.5 + 0.3 * std::sin(9.0 * x))});
    }
  return p;
}

std::string reason_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const sogmm::format::FormatError& e) {
    return e.reason();
  } catch (const sogmm::Error& e) {
    return std::string("error: ") + e.what();
  }
  return "accepted";
}

TEST(MapDeltaFile, RoundTripIsBitExactAndReadersKeepApart) {
  sogmm::MapOptions o;
  o.batch_size = 1000;
  o.fit.em.threads = 1;
  sogmm::Map sender(o);
  const sogmm::Pose id = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  sogmm::Map receiver;
  for (int frame = 0; frame < 3; ++frame) {
    const std::vector<float> p = wall(frame == 1 ? 20 : 40, 0.25 * frame);  // frame 1 only pends
    sender.insert_points({p.data(), p.size() / 4}, id);
    const sogmm::MapDelta d = sender.delta_since(receiver.revision());
    const std::vector<std::uint8_t> bytes = sogmm::format::delta_to_bytes(d);
    const sogmm::MapDelta back = sogmm::format::delta_from_bytes(bytes.data(), bytes.size());
    ASSERT_EQ(back.model.gmm.weights.size(), d.model.gmm.weights.size());
    // A delta of a frame that only pends carries no component: memcmp on
    // the empty vectors' null data() is undefined (UBSan), so compare only
    // what there is.
    EXPECT_TRUE(d.model.gmm.covariances.empty() ||
                std::memcmp(back.model.gmm.covariances.data(), d.model.gmm.covariances.data(),
                            d.model.gmm.covariances.size() * sizeof(float)) == 0);
    EXPECT_EQ(back.digest, d.digest);
    const sogmm::format::FileInfo info = sogmm::format::read_info(bytes.data(), bytes.size(),
                                                                  sogmm::format::ReadOptions{});
    EXPECT_EQ(info.features_required, 3u);  // map_delta and packed_key_values (section 2.5.1)
    EXPECT_EQ(info.format_minor, 2u);
    // A model reader refuses a delta; a delta reader refuses a model and a
    // delta cut short.
    EXPECT_EQ(reason_of([&] { sogmm::format::from_bytes(bytes.data(), bytes.size()); }), "unsupported_feature");
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.end() - 5);
    EXPECT_EQ(reason_of([&] { sogmm::format::delta_from_bytes(cut.data(), cut.size()); }), "truncated");
    receiver.apply_delta(back);
    if (frame == 1) {
      EXPECT_TRUE(d.ops.empty()) << "a frame that only pends carries no component";
    }
  }
  EXPECT_EQ(receiver.model().gmm.weights, sender.model().gmm.weights);
  sender.flush();
  const std::vector<std::uint8_t> model = sogmm::format::to_bytes(sender.to_model());
  EXPECT_EQ(reason_of([&] { sogmm::format::delta_from_bytes(model.data(), model.size()); }), "not_a_delta");
}

// A delta with frame lines and a removal: two inserts of a wall, the second
// refitting part of the first.
sogmm::MapDelta two_insert_delta() {
  sogmm::MapOptions o;
  o.batch_size = 1000;
  o.fit.em.threads = 1;
  sogmm::Map sender(o);
  const sogmm::Pose id = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.125, 0, 0, 0, 1};
  for (int frame = 0; frame < 2; ++frame) {
    const std::vector<float> p = wall(40, 0.25 * frame);
    sender.insert_points({p.data(), p.size() / 4}, id);
  }
  return sender.delta_since(0);
}

// `file` with the one occurrence of `from` in its metadata block replaced by
// `to` (same length) and the block's CRC-32C recomputed.
std::vector<std::uint8_t> patched(std::vector<std::uint8_t> file, const std::string& from, const std::string& to) {
  EXPECT_EQ(from.size(), to.size());
  const std::uint32_t len = file[24] | file[25] << 8 | file[26] << 16 | static_cast<std::uint32_t>(file[27]) << 24;
  const std::string meta(file.begin() + 32, file.begin() + 32 + len);
  const std::size_t at = meta.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(meta.find(from, at + 1), std::string::npos) << from;
  std::copy(to.begin(), to.end(), file.begin() + 32 + static_cast<std::ptrdiff_t>(at));
  sogmm::format::detail::refresh_metadata_crc(file);
  return file;
}

TEST(MapDeltaFile, PackedKeyValuesAreSmallerAndAFormat11DeltaStillReads) {
  const sogmm::MapDelta d = two_insert_delta();
  ASSERT_FALSE(d.frames.empty());
  const std::vector<std::uint8_t> packed = sogmm::format::delta_to_bytes(d);
  const std::vector<std::uint8_t> old = sogmm::format::detail::encode(sogmm::delta_to_model(d), {},
                                                                      sogmm::format::detail::map_delta_tweaks_1_1());
  // The same delta either way: keys, steps, frame lines, digest and bits.
  for (const auto* bytes : {&packed, &old}) {
    const sogmm::MapDelta back = sogmm::format::delta_from_bytes(bytes->data(), bytes->size());
    EXPECT_EQ(back.frames, d.frames);
    EXPECT_EQ(back.digest, d.digest);
    EXPECT_EQ(back.ops.size(), d.ops.size());
    EXPECT_EQ(back.model.key_values, d.model.key_values);
    EXPECT_EQ(back.model.gmm.weights, d.model.gmm.weights);
  }
  const sogmm::format::FileInfo info = sogmm::format::read_info(old.data(), old.size());
  EXPECT_EQ(info.format_minor, 1u);
  EXPECT_EQ(info.features_required, 1u);
  // The packed form stores the frame and step text compressed: the packed
  // file is smaller by at least half the text's size.
  EXPECT_LT(packed.size() + d.frames.size() / 2, old.size()) << packed.size() << " vs " << old.size();
}

TEST(MapDeltaFile, Step20RefusesABadPackedEntry) {
  const std::vector<std::uint8_t> good = sogmm::format::delta_to_bytes(two_insert_delta());
  const sogmm::format::FileInfo info = sogmm::format::read_info(good.data(), good.size());
  const std::string* entry = sogmm::find_value(info.metadata, sogmm::format::kPackedKeyValuesKey);
  ASSERT_NE(entry, nullptr);
  ASSERT_EQ(entry->substr(0, 2), "1 ");  // zstd
  std::istringstream fields(*entry);
  std::uint64_t codec = 0, stored = 0, decoded = 0, crc = 0;
  fields >> codec >> stored >> decoded >> crc;
  auto with = [&](std::uint64_t c, std::uint64_t s, std::uint64_t d, std::uint64_t x) {
    std::string text = std::to_string(c) + " " + std::to_string(s) + " " + std::to_string(d) + " " + std::to_string(x);
    return patched(good, *entry, text);
  };
  auto reason = [](const std::vector<std::uint8_t>& f, sogmm::format::ReadOptions o = {}) {
    return reason_of([&] { sogmm::format::delta_from_bytes(f.data(), f.size(), o); });
  };
  EXPECT_EQ(reason(good), "accepted");
  EXPECT_EQ(reason(with(2, stored, decoded, crc)), "bad_metadata");                  // unknown codec
  EXPECT_EQ(reason(with(0, stored, decoded, crc)), "bad_layout");                    // raw, lengths differ
  EXPECT_EQ(reason(with(codec, stored, decoded, crc ^ 1)), "checksum_mismatch");
  // (+1 keeps the number of digits here: patched() checks the lengths agree.)
  EXPECT_EQ(reason(with(codec, stored, decoded + 1, crc)), "decompression_failed");
  // The covariances end where the packed bytes start: one more byte overlaps.
  EXPECT_EQ(reason(with(codec, stored + 1, decoded, crc)), "bad_layout");
  EXPECT_EQ(reason(patched(good, sogmm::format::kPackedKeyValuesKey, "packed_key_valueZ")), "bad_metadata");
  sogmm::format::ReadOptions small;
  small.max_decoded_bytes = info.weights.decoded_length + info.means.decoded_length +
                            info.covariances.decoded_length + decoded - 1;
  EXPECT_EQ(reason(good, small), "limit");
  // A model reader does not know bit 1 either.
  EXPECT_EQ(reason_of([&] { sogmm::format::from_bytes(good.data(), good.size()); }), "unsupported_feature");
}

}  // namespace
