// The frame record of a map file (spec/format.md section 2.3.2, format 1.3,
// feature bit 3) and step 21 of section 9: a map's `map_frames` text leaves
// the file as binary64 rows and comes back byte for byte; a map loaded from
// the file holds bitwise the frames of the map saved and answers occupancy
// bitwise alike; text the record cannot give back stays text; a format 1.0
// map still loads; a hostile record is refused with the reason of its step.
//
// Numerical part (occupancy of the saved and the loaded map): the test runs
// under SOGMM_ISA=sse2, avx2 and the default (AVX-512 here). Both maps answer
// through the same kernel in one run from bitwise the same components, frames
// and camera, so "no bit differs" holds on every kernel.
// Mutations tried: the reader's "%.17g" as "%.16g" (round trip fails: text
// differs); step 21e's CRC compared with crc ^ 1 (the good file is refused);
// recorded_pose() with precision ignored (grid and bound checks fail).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "../core/plane_scene.hpp"
#include "frame_record.hpp"
#include "internal.hpp"
#include "sogmm/format.hpp"
#include "sogmm/map.hpp"
#include "sogmm/occupancy.hpp"
#include "test_support.hpp"

namespace {

namespace fmt = sogmm::format;

std::string reason_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const fmt::FormatError& e) {
    return e.reason();
  } catch (const sogmm::Error& e) {
    return std::string("error: ") + e.what();
  }
  return "accepted";
}

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Frame lines as a map writes them, with values of every kind.
std::string frame_lines() {
  const double poses[3][12] = {
      {1, -0.0, 0, 0.5, 0, 0.96592582628906831, 0.25881904510252074, 1e-300, -0.0, -0.25881904510252074,
       0.96592582628906831, 1234567.875},
      {0.9659271240234375, 4.9406564584124654e-324, 0.1, 1e17, 0.3, 2.0 / 3, -1.0 / 3, -1e-5, 1e-4, 1.5e-300, 1, -2},
      {0.6, 0.8, 0, 12345.678, -0.8, 0.6, 0, -0.000123, 0, 0, 1, 6.25e-2}};
  const char* counts[3][3] = {{"12288", "12288", "6"}, {"9007199254740992", "0", "6"}, {"7", "3", "41"}};
  std::string text;
  for (int i = 0; i < 3; ++i) {
    text += std::to_string(i) + " " + counts[i][0] + " " + counts[i][1];
    for (double v : poses[i]) text += " " + g17(v);
    text += std::string(" ") + counts[i][2] + "\n";
  }
  return text;
}

sogmm::Model map_model(const std::string& frames) {
  sogmm::Model m = sogmm::test::synthetic_model(12, 5);
  m.key_values = {{"coordinate_frame", "world"}, {"map_frames", frames}, {"map_options", "novelty=1"}, {"", "x"}};
  return m;
}

TEST(FrameRecord, KeyValuesComeBackByteForByte) {
  const sogmm::Model m = map_model(frame_lines());
  for (const bool compress : {true, false}) {
    fmt::WriteOptions w;
    w.compress = compress;
    const std::vector<std::uint8_t> bytes = fmt::to_bytes(m, w);
    const fmt::FileInfo info = fmt::read_info(bytes.data(), bytes.size());
    EXPECT_EQ(info.format_minor, 5u);  // 1.3 with the axis lists left out (spec/format.md section 7)
    EXPECT_EQ(info.features_required, 0xAu);  // packed_key_values and frame_record
    const sogmm::Model back = fmt::from_bytes(bytes.data(), bytes.size());
    EXPECT_EQ(back.key_values, m.key_values) << "compress " << compress;
    EXPECT_TRUE(sogmm::test::bit_equal(back, m));
    // The numbers are binary in the file: no pose text is left in it.
    const std::string file(bytes.begin(), bytes.end());
    EXPECT_EQ(file.find("0.96592582628906831"), std::string::npos);
  }
}

TEST(FrameRecord, TextTheRecordCannotGiveBackStaysText) {
  const std::string good = frame_lines();
  const std::string line15 = "0 5 5 1 0 0 0 0 1 0 0 0 0 1 0\n";  // before component counts were recorded
  std::string short_digits = good;
  short_digits.replace(short_digits.find(g17(0.1)), g17(0.1).size(), "0.1");  // not %.17g
  std::string not_from_0 = good;
  not_from_0[0] = '1';
  std::string huge_count = good;
  huge_count.replace(huge_count.find("9007199254740992"), 16, "9007199254740993");  // 2^53 + 1
  for (const std::string& text : {line15, short_digits, not_from_0, huge_count, good.substr(0, good.size() - 1),
                                  std::string("0 1 1 nan 0 0 0 0 1 0 0 0 0 1 0 1\n"), std::string()}) {
    const sogmm::Model m = map_model(text);
    const std::vector<std::uint8_t> bytes = fmt::to_bytes(m);
    const fmt::FileInfo info = fmt::read_info(bytes.data(), bytes.size());
    EXPECT_EQ(info.features_required, 0u) << text;
    EXPECT_EQ(info.format_minor, 0u);
    EXPECT_EQ(fmt::from_bytes(bytes.data(), bytes.size()).key_values, m.key_values);
  }
  // A model that already holds a key `map_frame_record` (the record's
  // locating key; a reader takes the first) keeps its text, wherever the key
  // stands: compacted, it was refused by its own reader (bad_metadata).
  for (const bool before : {true, false}) {
    sogmm::Model m = map_model(good);
    const std::pair<std::string, std::string> user{"map_frame_record", "hello"};
    m.key_values.insert(before ? m.key_values.begin() : m.key_values.end(), user);
    const std::vector<std::uint8_t> bytes = fmt::to_bytes(m);
    EXPECT_EQ(fmt::read_info(bytes.data(), bytes.size()).features_required, 0u) << before;
    EXPECT_EQ(fmt::from_bytes(bytes.data(), bytes.size()).key_values, m.key_values) << before;
  }
}

// The plane scene seen from three turned and moved poses (entries that are
// not on any short grid), fitted into a map with the given precision.
sogmm::Map three_frame_map(double precision) {
  sogmm::MapOptions o;
  o.novelty = false;
  o.component_precision = precision;
  o.depth.decimate = 2;  // 768 points a frame: a fast fit
  sogmm::Map map(o);
  const sogmm::Camera& cam = sogmm_test::kPlaneCamera;
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(cam.width * cam.height),
                                   static_cast<std::uint16_t>(sogmm_test::kPlaneZ * 1000));
  std::vector<float> gray(depth.size(), 0.5f);
  for (int k = 0; k < 3; ++k) {
    const double yaw = 0.05 * (k - 1.5), c = std::cos(yaw), s = std::sin(yaw);
    const sogmm::Pose pose = {c, 0, s, 0.1 * k - 0.13, 0, 1, 0, 0.037 * k, -s, 0, c, -0.05 * k, 0, 0, 0, 1};
    map.insert_rgbd({depth.data(), gray.data(), cam}, pose);
  }
  map.flush();
  return map;
}

// Occupancy of a lattice in front of, on and behind the plane.
std::vector<double> lattice_occupancy(const sogmm::Map& map, std::vector<std::uint8_t>& state) {
  std::vector<float> xyz;
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 25; ++k) xyz.insert(xyz.end(), {-1.4f + 0.2f * i, -0.9f + 0.18f * j, 0.2f + 0.1f * k});
  const std::size_t n = xyz.size() / 3;
  std::vector<double> p(n);
  state.assign(n, 9);
  sogmm::occupancy(map, xyz.data(), n, p.data(), state.data());
  return p;
}

TEST(FrameRecord, ALoadedMapHoldsTheFramesAndAnswersBitwiseAlike) {
  for (const double precision : {0.0, 0.5}) {
    const sogmm::Map map = three_frame_map(precision);
    const std::vector<std::uint8_t> bytes = fmt::to_bytes(map.to_model());
    EXPECT_EQ(fmt::read_info(bytes.data(), bytes.size()).features_required, 0xAu);
    // The same map as format 1.0 text (what earlier writers wrote) reads alike.
    fmt::detail::Tweaks text_form;
    text_form.compact_maps = false;
    const std::vector<std::uint8_t> old = fmt::detail::encode(map.to_model(), {}, text_form);
    EXPECT_EQ(fmt::read_info(old.data(), old.size()).features_required, 0u);
    EXPECT_LT(bytes.size(), old.size());
    std::vector<std::uint8_t> s0, s1;
    const std::vector<double> p0 = lattice_occupancy(map, s0);
    for (const auto* file : {&bytes, &old}) {
      const sogmm::Map loaded = sogmm::Map::from_model(fmt::from_bytes(file->data(), file->size()));
      ASSERT_EQ(loaded.frames().size(), map.frames().size());
      for (std::size_t f = 0; f < map.frames().size(); ++f) {
        const sogmm::FrameStats &a = map.frames()[f], &b = loaded.frames()[f];
        EXPECT_EQ(std::memcmp(a.pose.data(), b.pose.data(), sizeof a.pose), 0) << "frame " << f;
        EXPECT_EQ(a.n_points, b.n_points);
        EXPECT_EQ(a.n_novel, b.n_novel);
        EXPECT_EQ(a.n_components, b.n_components);
      }
      const std::vector<double> p1 = lattice_occupancy(loaded, s1);
      EXPECT_EQ(std::memcmp(p0.data(), p1.data(), p0.size() * sizeof(double)), 0) << "precision " << precision;
      EXPECT_EQ(s0, s1);
    }
    // With a precision, the recorded poses lie on the grid 2^-16 within
    // 2^-17 of the poses given (three_frame_map's); without, they are those.
    for (std::size_t k = 0; k < map.frames().size(); ++k) {
      const double yaw = 0.05 * (static_cast<double>(k) - 1.5);
      const double given[3] = {std::cos(yaw), std::sin(yaw), 0.1 * static_cast<double>(k) - 0.13};
      const double recorded[3] = {map.frames()[k].pose[0], map.frames()[k].pose[2], map.frames()[k].pose[3]};
      for (int i = 0; i < 3; ++i) {
        if (precision > 0) {
          EXPECT_LE(std::abs(recorded[i] - given[i]), std::ldexp(1.0, -17));
          EXPECT_EQ(std::ldexp(recorded[i], 16), std::nearbyint(std::ldexp(recorded[i], 16)));
        } else {
          EXPECT_EQ(recorded[i], given[i]);
        }
      }
    }
  }
}

// The raw record (codec NONE) of `rows` and its locating value.
std::pair<std::vector<std::uint8_t>, std::string> raw_record(const std::vector<double>& rows) {
  fmt::WriteOptions raw;
  raw.compress = false;
  fmt::detail::FrameRecord r = fmt::detail::encode_frame_rows(rows, raw);
  return {r.stored, r.entry.second};
}

TEST(FrameRecord, Step21RefusesAHostileRecord) {
  const sogmm::Model m = map_model(frame_lines());
  const std::vector<std::uint8_t> good = fmt::to_bytes(m);
  auto with = [&](const std::string& entry, const std::vector<std::uint8_t>* stored = nullptr) {
    fmt::detail::Tweaks t;
    t.frame_record_entry = entry;
    if (stored) t.frame_record_stored = *stored;
    return fmt::detail::encode(m, {}, t);
  };
  auto reason = [](const std::vector<std::uint8_t>& f, fmt::ReadOptions o = {}) {
    return reason_of([&] { fmt::from_bytes(f.data(), f.size(), o); });
  };
  // The record's rows, from the text, and its raw stored bytes.
  const std::vector<double> rows = fmt::detail::frame_rows(m.key_values[1].second);
  ASSERT_EQ(rows.size(), 45u);
  const auto [raw, raw_entry] = raw_record(rows);
  ASSERT_EQ(raw_entry.substr(0, 8), "0 360 36");
  const std::string crc_text = raw_entry.substr(raw_entry.rfind(' ') + 1);
  const std::uint32_t crc = static_cast<std::uint32_t>(std::stoul(crc_text));
  EXPECT_EQ(reason(with(raw_entry, &raw)), "accepted");
  EXPECT_EQ(fmt::from_bytes(good.data(), good.size()).key_values, m.key_values);
  // 21a: the entry.
  EXPECT_EQ(reason(with("2 360 360 " + std::to_string(crc), &raw)), "bad_metadata");  // unknown codec
  EXPECT_EQ(reason(with("0 360 360", &raw)), "bad_metadata");
  const std::vector<std::uint8_t> raw_short(raw.begin(), raw.begin() + 352);
  EXPECT_EQ(reason(with("0 352 352 " + std::to_string(crc), &raw_short)), "bad_metadata");  // not 120 F
  // 21b: the cap counts the record.
  fmt::ReadOptions small;
  const std::vector<std::uint8_t> raw_file = with(raw_entry, &raw);
  const fmt::FileInfo info = fmt::read_info(raw_file.data(), raw_file.size());
  std::uint64_t packed = 0;
  {
    std::istringstream f(*sogmm::find_value(info.metadata, fmt::kPackedKeyValuesKey));
    std::uint64_t codec, stored;
    f >> codec >> stored >> packed;
  }
  small.max_decoded_bytes =
      info.weights.decoded_length + info.means.decoded_length + info.covariances.decoded_length + packed + 359;
  EXPECT_EQ(reason(raw_file, small), "limit");
  small.max_decoded_bytes += 1;
  EXPECT_EQ(reason(raw_file, small), "accepted");
  // 21c: layout. One more stored byte overlaps the covariances; a raw record
  // must be its decoded length; a length beyond the body lies outside it.
  std::vector<std::uint8_t> raw_plus(raw);
  raw_plus.push_back(0);
  EXPECT_EQ(reason(with("0 361 360 " + std::to_string(crc), &raw)), "bad_layout");
  EXPECT_EQ(reason(with("0 361 360 " + std::to_string(crc), &raw_plus)), "bad_layout");
  EXPECT_EQ(reason(with("0 99999999 360 " + std::to_string(crc), &raw)), "bad_layout");
  // 21d: zstd bytes that are not a frame.
  EXPECT_EQ(reason(with("1 360 360 " + std::to_string(crc), &raw)), "decompression_failed");
  // 21e: the CRC-32C of the canonical bytes.
  EXPECT_EQ(reason(with("0 360 360 " + std::to_string(crc ^ 1), &raw)), "checksum_mismatch");
  std::vector<std::uint8_t> flipped(raw);
  flipped[100] ^= 0x10;
  EXPECT_EQ(reason(with(raw_entry, &flipped)), "checksum_mismatch");
  fmt::ReadOptions unverified;
  unverified.verify_checksums = false;
  EXPECT_EQ(reason(with(raw_entry, &flipped), unverified), "accepted");
  // 21f: a count that is not an integer, a pose entry that is not finite.
  for (const std::size_t at : {std::size_t{15}, std::size_t{15 + 5}}) {
    std::vector<double> bad = rows;
    bad[at] = at == 15 ? 0.5 : INFINITY;
    const auto [b, entry] = raw_record(bad);
    EXPECT_EQ(reason(with(entry, &b)), "bad_metadata") << at;
  }
  // Bit 3 without the entry; the file cut short.
  fmt::detail::Tweaks no_entry;
  no_entry.compact_maps = false;
  no_entry.minor = 3;
  no_entry.features_required = 0xA;
  no_entry.pack_key_values = true;
  EXPECT_EQ(reason(fmt::detail::encode(m, {}, no_entry)), "bad_metadata");
  const std::vector<std::uint8_t> cut(good.begin(), good.end() - 7);
  EXPECT_EQ(reason(cut), "truncated");
}

}  // namespace
