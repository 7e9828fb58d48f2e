// Loading a real RGB-D frame for the core tests (OpenCV, tests only): the
// depth image, its gray and intrinsics, and its back-projected points.
#pragma once

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sogmm/camera.hpp"
#include "sogmm/point_cloud.hpp"

namespace sogmm_test {

struct Frame {
  cv::Mat depth;  // CV_16U
  sogmm::GrayImage gray;
  sogmm::Camera camera;
};

inline Frame load_frame(const std::filesystem::path& color, const std::filesystem::path& depth, const std::filesystem::path& intrinsics) {
  Frame f;
  cv::Mat bgr = cv::imread(color.string(), cv::IMREAD_COLOR);
  f.depth = cv::imread(depth.string(), cv::IMREAD_UNCHANGED);
  if (bgr.empty() || f.depth.empty() || f.depth.type() != CV_16U)
    throw std::runtime_error("cannot read frame " + color.string() + " / " + depth.string());
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  if (!rgb.isContinuous()) rgb = rgb.clone();
  f.gray = sogmm::gray_from_rgb_image(rgb.ptr<std::uint8_t>(), rgb.cols, rgb.rows);
  f.camera = sogmm::read_intrinsics_json(intrinsics.string());
  return f;
}

inline sogmm::PointCloud cloud_of(const Frame& f, double depth_scale, int d) {
  if (!f.depth.isContinuous()) throw std::runtime_error("depth not continuous");
  sogmm::RgbdView view{f.depth.ptr<std::uint16_t>(), f.gray.pixels.data(), f.camera};
  sogmm::DepthOptions o;
  o.depth_scale = depth_scale;
  o.decimate = d;
  return sogmm::backproject(view, o);
}

}  // namespace sogmm_test
