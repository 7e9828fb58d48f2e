// RGB-D frames from image files: PNG depth, PNG or JPEG colour, decoded by
// the library itself (libpng, libjpeg-turbo) with fixed decoder settings, so
// that every front end (C, Python, Rust, Go, the CLI) gets the same bytes
// from the same file and therefore the same model.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sogmm::format {

/// Largest image accepted, in pixels (2^26, as many as one fit takes: 8192 x
/// 8192). Checked from the header, before the pixels are allocated, so a
/// hostile header cannot make the decoder allocate without bound.
constexpr std::uint64_t kMaxFramePixels = std::uint64_t{1} << 26;

/// A decoded depth image: width * height raw values, row-major.
struct DepthImage {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint16_t> pixels;
};

/// A decoded colour image: width * height * channels bytes, row-major,
/// channels 1 (gray) or 3 (interleaved R, G, B).
struct ColorImage {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  int channels = 0;
  std::vector<std::uint8_t> bytes;
};

/// Decodes a depth PNG: one channel, 16 bits (or 8 bits, widened to 16 with
/// the same values). `name` names the image in messages. Errors (sogmm::Error):
/// not a PNG, truncated or corrupt -> Format; colour, alpha, a palette or
/// another bit depth -> InvalidData; more than kMaxFramePixels -> Limit.
DepthImage decode_depth_png(const void* data, std::size_t size, const std::string& name);

/// Decodes a colour PNG or JPEG (told apart by their signatures). PNG: 8-bit
/// gray -> 1 channel; 8-bit RGB, a palette, or 1/2/4-bit gray -> expanded to
/// 3 resp. 1 channels; an alpha channel is dropped; no gamma correction.
/// JPEG: gray -> 1 channel, YCbCr/RGB -> 3 channels with libjpeg's accurate
/// integer IDCT and its default upsampling. Errors: neither format, truncated
/// or corrupt (a JPEG warning counts as corrupt, as does a progressive JPEG
/// of more than 500 scans) -> Format; 16-bit colour, CMYK -> InvalidData; more
/// than kMaxFramePixels -> Limit.
ColorImage decode_color_image(const void* data, std::size_t size, const std::string& name);

/// The files' versions: Io when a file cannot be opened or is not a regular
/// file (a FIFO is refused, never waited on); messages name the path.
DepthImage read_depth_png(const std::string& path);
ColorImage read_color_image(const std::string& path);

}  // namespace sogmm::format
