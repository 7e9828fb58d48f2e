// The library's frame reader (sogmm/frame_image.hpp): pixels as written by
// libpng's / libjpeg's encoders, each PNG layout, and hostile files
// (truncated at every length, every byte corrupted, huge headers) that must
// end in a sogmm::Error with the documented code, never a crash.
#include <gtest/gtest.h>
#include <png.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "image_writers.hpp"
#include "sogmm/error.hpp"
#include "sogmm/frame_image.hpp"

namespace {

using sogmm::ErrorCode;
using sogmm::format::decode_color_image;
using sogmm::format::decode_depth_png;

template <typename F>
ErrorCode code_of(F&& f) {
  try {
    f();
  } catch (const sogmm::Error& e) {
    return e.code();
  }
  ADD_FAILURE() << "no sogmm::Error thrown";
  return ErrorCode::Cancelled;
}

std::vector<std::uint8_t> ramp(std::size_t n, int mul) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>((i * mul + 7) % 256);
  return v;
}

// 16-bit depth values and their big-endian PNG samples.
std::vector<std::uint16_t> depth_values(int w, int h) {
  std::vector<std::uint16_t> d(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = static_cast<std::uint16_t>((i * 4099u + 1u) % 65536u);
  d[0] = 0;
  d[1] = 65535;
  d[2] = 256;
  return d;
}
std::vector<std::uint8_t> big_endian(const std::vector<std::uint16_t>& d) {
  std::vector<std::uint8_t> b;
  for (std::uint16_t v : d) {
    b.push_back(static_cast<std::uint8_t>(v >> 8));
    b.push_back(static_cast<std::uint8_t>(v & 0xFF));
  }
  return b;
}

TEST(FrameImage, Depth16IsReadExactlyPlainAndInterlaced) {
  const int w = 13, h = 9;
  const auto d = depth_values(w, h);
  for (bool interlace : {false, true}) {
    const auto png = sogmm_test::write_png(w, h, PNG_COLOR_TYPE_GRAY, 16, big_endian(d), interlace);
    const auto img = decode_depth_png(png.data(), png.size(), "d");
    EXPECT_EQ(img.width, 13u);
    EXPECT_EQ(img.height, 9u);
    EXPECT_EQ(img.pixels, d) << "interlace " << interlace;
  }
}

TEST(FrameImage, Depth8IsWidenedWithTheSameValues) {
  const auto g = ramp(6 * 4, 37);
  const auto png = sogmm_test::write_png(6, 4, PNG_COLOR_TYPE_GRAY, 8, g);
  const auto img = decode_depth_png(png.data(), png.size(), "d");
  ASSERT_EQ(img.pixels.size(), g.size());
  for (std::size_t i = 0; i < g.size(); ++i) EXPECT_EQ(img.pixels[i], g[i]);
}

TEST(FrameImage, DepthRefusesColourAlphaPaletteOtherBitDepthsAndJpeg) {
  const auto rgb = sogmm_test::write_png(4, 4, PNG_COLOR_TYPE_RGB, 8, ramp(48, 5));
  const auto ga = sogmm_test::write_png(4, 4, PNG_COLOR_TYPE_GRAY_ALPHA, 8, ramp(32, 5));
  const auto g4 = sogmm_test::write_png(4, 4, PNG_COLOR_TYPE_GRAY, 4, ramp(8, 5));
  const auto pal = sogmm_test::write_png(4, 4, PNG_COLOR_TYPE_PALETTE, 8, std::vector<std::uint8_t>(16, 0), false,
                                         {1, 2, 3});
  const auto jpg = sogmm_test::write_jpeg(8, 8, 1, std::vector<std::uint8_t>(64, 9));
  for (const auto* f : {&rgb, &ga, &g4, &pal, &jpg})
    EXPECT_EQ(code_of([&] { decode_depth_png(f->data(), f->size(), "d"); }), ErrorCode::InvalidData);
  try {
    decode_depth_png(rgb.data(), rgb.size(), "some/depth.png");
  } catch (const sogmm::Error& e) {
    EXPECT_NE(std::string(e.what()).find("some/depth.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("one channel"), std::string::npos) << e.what();
  }
}

TEST(FrameImage, ColourPngLayouts) {
  const auto gray = ramp(5 * 3, 11);
  const auto gpng = sogmm_test::write_png(5, 3, PNG_COLOR_TYPE_GRAY, 8, gray);
  auto img = decode_color_image(gpng.data(), gpng.size(), "c");
  EXPECT_EQ(img.channels, 1);
  EXPECT_EQ(img.bytes, gray);

  const auto rgb = ramp(5 * 3 * 3, 13);
  const auto rpng = sogmm_test::write_png(5, 3, PNG_COLOR_TYPE_RGB, 8, rgb, true);
  img = decode_color_image(rpng.data(), rpng.size(), "c");
  EXPECT_EQ(img.channels, 3);
  EXPECT_EQ(img.bytes, rgb);

  // Alpha is dropped: RGBA -> RGB, gray + alpha -> gray.
  const auto rgba = ramp(5 * 3 * 4, 17);
  const auto apng = sogmm_test::write_png(5, 3, PNG_COLOR_TYPE_RGB_ALPHA, 8, rgba);
  img = decode_color_image(apng.data(), apng.size(), "c");
  ASSERT_EQ(img.channels, 3);
  for (std::size_t i = 0; i < 15; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(img.bytes[3 * i + c], rgba[4 * i + c]);
  const auto ga = ramp(5 * 3 * 2, 19);
  const auto gapng = sogmm_test::write_png(5, 3, PNG_COLOR_TYPE_GRAY_ALPHA, 8, ga);
  img = decode_color_image(gapng.data(), gapng.size(), "c");
  ASSERT_EQ(img.channels, 1);
  for (std::size_t i = 0; i < 15; ++i) EXPECT_EQ(img.bytes[i], ga[2 * i]);

  // A palette (with transparency) becomes its RGB entries.
  const std::vector<std::uint8_t> palette = {10, 20, 30, 200, 100, 50};
  const std::vector<std::uint8_t> index = {0, 1, 1, 0, 1, 0};
  const auto ppng = sogmm_test::write_png(3, 2, PNG_COLOR_TYPE_PALETTE, 8, index, false, palette, {0, 128});
  img = decode_color_image(ppng.data(), ppng.size(), "c");
  ASSERT_EQ(img.channels, 3);
  for (std::size_t i = 0; i < index.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(img.bytes[3 * i + c], palette[3 * index[i] + c]);

  // 2-bit gray is expanded by replication: 0, 1, 2, 3 -> 0, 85, 170, 255.
  const auto g2 = sogmm_test::write_png(4, 1, PNG_COLOR_TYPE_GRAY, 2, {0x1B});  // samples 0, 1, 2, 3
  img = decode_color_image(g2.data(), g2.size(), "c");
  EXPECT_EQ(img.bytes, (std::vector<std::uint8_t>{0, 85, 170, 255}));

  const auto rgb16 = sogmm_test::write_png(2, 2, PNG_COLOR_TYPE_RGB, 16, ramp(24, 3));
  EXPECT_EQ(code_of([&] { decode_color_image(rgb16.data(), rgb16.size(), "c"); }), ErrorCode::InvalidData);
}

TEST(FrameImage, JpegGrayAndRgb) {
  // A constant gray image is one DC value per block: decoded exactly.
  const auto gjpg = sogmm_test::write_jpeg(16, 8, 1, std::vector<std::uint8_t>(128, 131));
  auto img = decode_color_image(gjpg.data(), gjpg.size(), "c");
  EXPECT_EQ(img.channels, 1);
  EXPECT_EQ(img.bytes, std::vector<std::uint8_t>(128, 131));
  // Constant RGB goes through YCbCr and back: within 2 of each channel.
  std::vector<std::uint8_t> rgb;
  for (int i = 0; i < 16 * 8; ++i) rgb.insert(rgb.end(), {200, 100, 50});
  for (bool progressive : {false, true}) {
    const auto cjpg = sogmm_test::write_jpeg(16, 8, 3, rgb, progressive);
    img = decode_color_image(cjpg.data(), cjpg.size(), "c");
    ASSERT_EQ(img.channels, 3);
    ASSERT_EQ(img.bytes.size(), rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) EXPECT_NEAR(img.bytes[i], rgb[i], 2) << i;
  }
}

TEST(FrameImage, EveryTruncationIsAFormatError) {
  const auto png = sogmm_test::write_png(9, 7, PNG_COLOR_TYPE_GRAY, 16, big_endian(depth_values(9, 7)));
  for (std::size_t n = 0; n < png.size(); ++n)
    EXPECT_EQ(code_of([&] { decode_depth_png(png.data(), n, "d"); }), ErrorCode::Format) << n;
  const auto rgb = sogmm_test::write_png(9, 7, PNG_COLOR_TYPE_RGB, 8, ramp(9 * 7 * 3, 5), true);
  for (std::size_t n = 0; n < rgb.size(); ++n)
    EXPECT_EQ(code_of([&] { decode_color_image(rgb.data(), n, "c"); }), ErrorCode::Format) << n;
  const auto jpg = sogmm_test::write_jpeg(24, 16, 3, ramp(24 * 16 * 3, 7));
  for (std::size_t n = 0; n < jpg.size(); ++n)
    EXPECT_EQ(code_of([&] { decode_color_image(jpg.data(), n, "c"); }), ErrorCode::Format) << n;
}

// Every byte inverted in turn: a decode or a sogmm::Error, nothing else.
TEST(FrameImage, EveryCorruptedByteDecodesOrFailsCleanly) {
  const auto png = sogmm_test::write_png(9, 7, PNG_COLOR_TYPE_GRAY, 16, big_endian(depth_values(9, 7)));
  const auto jpg = sogmm_test::write_jpeg(24, 16, 3, ramp(24 * 16 * 3, 7), true);
  for (const auto* f : {&png, &jpg}) {
    int failed = 0;
    for (std::size_t i = 0; i < f->size(); ++i) {
      std::vector<std::uint8_t> bad = *f;
      bad[i] ^= 0xFF;
      try {
        if (f == &png)
          (void)decode_depth_png(bad.data(), bad.size(), "d");
        else
          (void)decode_color_image(bad.data(), bad.size(), "c");
      } catch (const sogmm::Error&) {
        ++failed;
      }
    }
    EXPECT_GT(failed, 0);  // the signature bytes at least
  }
}

TEST(FrameImage, HugeDimensionsAreRefusedBeforeAllocation) {
  // A 20000 x 20000 PNG header (4e8 pixels > 2^26) with a valid CRC.
  auto png = sogmm_test::write_png(2, 2, PNG_COLOR_TYPE_GRAY, 16, std::vector<std::uint8_t>(8, 1));
  for (int k : {16, 20}) {
    png[k] = 0;
    png[k + 1] = 0;
    png[k + 2] = 0x4E;
    png[k + 3] = 0x20;
  }
  const uLong crc = crc32(0, png.data() + 12, 17);
  for (int b = 0; b < 4; ++b) png[29 + b] = static_cast<std::uint8_t>(crc >> (24 - 8 * b));
  EXPECT_EQ(code_of([&] { decode_depth_png(png.data(), png.size(), "d"); }), ErrorCode::Limit);

  // A JPEG whose frame header claims 60000 x 60000.
  auto jpg = sogmm_test::write_jpeg(8, 8, 1, std::vector<std::uint8_t>(64, 9));
  std::size_t sof = 2;
  while (sof + 1 < jpg.size() && !(jpg[sof] == 0xFF && jpg[sof + 1] == 0xC0)) ++sof;
  ASSERT_LT(sof + 9, jpg.size());
  for (int k : {5, 7}) {
    jpg[sof + k] = 0xEA;
    jpg[sof + k + 1] = 0x60;
  }
  EXPECT_EQ(code_of([&] { decode_color_image(jpg.data(), jpg.size(), "c"); }), ErrorCode::Limit);
}

TEST(FrameImage, FilesAreReadAsRegularFilesOnly) {
  char dir[] = "/tmp/sogmm_frame_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string fifo = std::string(dir) + "/fifo.png";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(code_of([&] { sogmm::format::read_depth_png(fifo); }), ErrorCode::Io);  // never waits for a writer
  EXPECT_EQ(code_of([&] { sogmm::format::read_color_image(std::string(dir) + "/missing.jpg"); }), ErrorCode::Io);
  EXPECT_EQ(code_of([&] { sogmm::format::read_depth_png(dir); }), ErrorCode::Io);
  unlink(fifo.c_str());
  rmdir(dir);
}

}  // namespace
