// Frame images: format dispatch, the size cap and the file versions of the
// decoders (image_decoders.hpp).
#include "sogmm/frame_image.hpp"
#include "sogmm/input_file.hpp"

#include "image_decoders.hpp"
#include "sogmm/error.hpp"

namespace sogmm::format {
namespace {
// A compressed image is smaller than its pixels (2^26 pixels x 3 bytes) plus
// the container's overhead; a larger file is refused before it is read.
constexpr std::uint64_t kMaxImageFileBytes = std::uint64_t{1} << 30;
}  // namespace

namespace detail {
void check_frame_size(std::uint64_t width, std::uint64_t height, const std::string& name) {
  require(width > 0 && height > 0, ErrorCode::Format, name + ": the image has no pixel (0 x 0)");
  require(width * height <= kMaxFramePixels, ErrorCode::Limit,
          name + ": image of " + std::to_string(width) + " x " + std::to_string(height) +
              " pixels exceeds the limit of " + std::to_string(kMaxFramePixels) + " pixels");
}
}  // namespace detail

DepthImage decode_depth_png(const void* data, std::size_t size, const std::string& name) {
  require(data != nullptr || size == 0, ErrorCode::InvalidArgument, name + ": no bytes");
  if (detail::is_png(data, size)) return detail::png_depth(data, size, name);
  require(!detail::is_jpeg(data, size), ErrorCode::InvalidData,
          name + ": a depth image must be a PNG (16-bit gray), this is a JPEG");
  throw Error(ErrorCode::Format, name + ": not a PNG image (" + std::to_string(size) + " bytes)");
}

ColorImage decode_color_image(const void* data, std::size_t size, const std::string& name) {
  require(data != nullptr || size == 0, ErrorCode::InvalidArgument, name + ": no bytes");
  if (detail::is_png(data, size)) return detail::png_color(data, size, name);
  if (detail::is_jpeg(data, size)) return detail::jpeg_color(data, size, name);
  throw Error(ErrorCode::Format, name + ": neither a PNG nor a JPEG image (" + std::to_string(size) + " bytes)");
}

DepthImage read_depth_png(const std::string& path) {
  const std::string bytes = read_input_file(path, "depth image", kMaxImageFileBytes);
  return decode_depth_png(bytes.data(), bytes.size(), path);
}

ColorImage read_color_image(const std::string& path) {
  const std::string bytes = read_input_file(path, "colour image", kMaxImageFileBytes);
  return decode_color_image(bytes.data(), bytes.size(), path);
}

}  // namespace sogmm::format
