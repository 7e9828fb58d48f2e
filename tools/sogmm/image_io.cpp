#include "image_io.hpp"

#include <cstdio>
#include <filesystem>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "file_util.hpp"
#include "sogmm/error.hpp"

namespace sogmm::tools {

namespace {
cv::Mat read_image(const std::string& path, int flags, const char* what) {
  require(std::filesystem::is_regular_file(path), ErrorCode::Io, path + ": cannot open " + what + " image (no such file)");
  cv::Mat img;
  try {
    img = cv::imread(path, flags);
  } catch (const cv::Exception&) {
    img.release();
  }
  require(!img.empty(), ErrorCode::Io, path + ": cannot decode " + what + " image");
  return img;
}
}  // namespace

namespace {
cv::Mat read_depth(const std::string& depth_path) {
  const cv::Mat depth = read_image(depth_path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR, "depth");
  require(depth.channels() == 1, ErrorCode::InvalidData,
          depth_path + ": depth image must have one channel, has " + std::to_string(depth.channels()));
  require(depth.depth() == CV_16U || depth.depth() == CV_8U, ErrorCode::InvalidData,
          depth_path + ": depth image must be 16-bit (or 8-bit) unsigned integers");
  return depth;
}

void copy_depth(const cv::Mat& depth, LoadedFrame& frame) {
  frame.width = depth.cols;
  frame.height = depth.rows;
  cv::Mat depth16;
  depth.convertTo(depth16, CV_16U);
  frame.depth.assign(static_cast<std::size_t>(frame.width) * frame.height, 0);
  for (int v = 0; v < frame.height; ++v)
    std::copy(depth16.ptr<std::uint16_t>(v), depth16.ptr<std::uint16_t>(v) + frame.width,
              frame.depth.begin() + static_cast<std::size_t>(v) * frame.width);
}
}  // namespace

LoadedFrame load_depth(const std::string& depth_path) {
  LoadedFrame frame;
  copy_depth(read_depth(depth_path), frame);
  frame.gray.assign(frame.depth.size(), 0.f);
  return frame;
}

LoadedFrame load_frame(const std::string& depth_path, const std::string& color_path) {
  const cv::Mat depth = read_depth(depth_path);
  const cv::Mat color = read_image(color_path, cv::IMREAD_UNCHANGED, "color");
  require(color.depth() == CV_8U, ErrorCode::InvalidData, color_path + ": color image must be 8-bit");
  require(color.cols == depth.cols && color.rows == depth.rows, ErrorCode::InvalidData,
          "images of different sizes: depth " + depth_path + " is " + std::to_string(depth.cols) + "x" +
              std::to_string(depth.rows) + ", color " + color_path + " is " + std::to_string(color.cols) + "x" +
              std::to_string(color.rows));

  LoadedFrame frame;
  copy_depth(depth, frame);

  cv::Mat rgb;
  switch (color.channels()) {
    case 1: rgb = color; break;
    case 3: cv::cvtColor(color, rgb, cv::COLOR_BGR2RGB); break;
    case 4: cv::cvtColor(color, rgb, cv::COLOR_BGRA2RGB); break;
    default:
      throw Error(ErrorCode::InvalidData, color_path + ": unsupported channel count " + std::to_string(color.channels()));
  }
  const cv::Mat packed = rgb.isContinuous() ? rgb : rgb.clone();
  const GrayImage gray = rgb.channels() == 1 ? gray_from_u8_image(packed.ptr<std::uint8_t>(0), frame.width, frame.height)
                                             : gray_from_rgb_image(packed.ptr<std::uint8_t>(0), frame.width, frame.height);
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
