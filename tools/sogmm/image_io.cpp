#include "image_io.hpp"

#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "file_util.hpp"
#include "sogmm/error.hpp"
#include "sogmm/frame_image.hpp"

namespace sogmm::tools {

namespace {
// The library's frame reader (sogmm/frame_image.hpp) decodes the files, so
// the CLI sees the pixels every binding sees.
void copy_depth(format::DepthImage depth, LoadedFrame& frame) {
  frame.width = static_cast<int>(depth.width);
  frame.height = static_cast<int>(depth.height);
  frame.depth = std::move(depth.pixels);
}
}  // namespace

LoadedFrame load_depth(const std::string& depth_path) {
  LoadedFrame frame;
  copy_depth(format::read_depth_png(depth_path), frame);
  frame.gray.assign(frame.depth.size(), 0.f);
  return frame;
}

LoadedFrame load_frame(const std::string& depth_path, const std::string& color_path) {
  format::DepthImage depth = format::read_depth_png(depth_path);
  const format::ColorImage color = format::read_color_image(color_path);
  require(color.width == depth.width && color.height == depth.height, ErrorCode::InvalidData,
          "images of different sizes: depth " + depth_path + " is " + std::to_string(depth.width) + "x" +
              std::to_string(depth.height) + ", color " + color_path + " is " + std::to_string(color.width) + "x" +
              std::to_string(color.height));
  LoadedFrame frame;
  copy_depth(std::move(depth), frame);
  const GrayImage gray = color.channels == 1 ? gray_from_u8_image(color.bytes.data(), frame.width, frame.height)
                                             : gray_from_rgb_image(color.bytes.data(), frame.width, frame.height);
  frame.gray = gray.pixels;
  return frame;
}

void write_png(const std::string& path, int width, int height, int channels, const std::uint8_t* data) {
  const cv::Mat img(height, width, channels == 3 ? CV_8UC3 : CV_8UC1, const_cast<std::uint8_t*>(data));
  std::vector<std::uint8_t> bytes;
  require(cv::imencode(".png", img, bytes), ErrorCode::Io, path + ": cannot encode PNG");
  write_file_atomic(path, bytes.data(), bytes.size());
}

void write_png16(const std::string& path, int width, int height, const std::uint16_t* data) {
  const cv::Mat img(height, width, CV_16UC1, const_cast<std::uint16_t*>(data));
  std::vector<std::uint8_t> bytes;
  require(cv::imencode(".png", img, bytes), ErrorCode::Io, path + ": cannot encode PNG");
  write_file_atomic(path, bytes.data(), bytes.size());
}

}  // namespace sogmm::tools
