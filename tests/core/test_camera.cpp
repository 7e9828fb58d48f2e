// Camera: decimation (equal to OpenCV INTER_NEAREST when d divides the size;
// any d: tests/core/test_scale_geometry.cpp), intrinsics, back-projection,
// depth range edges, gray, z-buffer projection, Open3D intrinsics JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sogmm/camera.hpp"
#include "test_util.hpp"

namespace {

// Every field of `c` against `want` (size exactly, intrinsics within 4 ULP).
void expect_camera(const sogmm::Camera& c, const sogmm::Camera& want) {
  EXPECT_EQ(c.width, want.width);
  EXPECT_EQ(c.height, want.height);
  EXPECT_DOUBLE_EQ(c.fx, want.fx);
  EXPECT_DOUBLE_EQ(c.fy, want.fy);
  EXPECT_DOUBLE_EQ(c.cx, want.cx);
  EXPECT_DOUBLE_EQ(c.cy, want.cy);
}

}  // namespace

TEST(Camera, DecimatedIntrinsics) {
  const sogmm::Camera c{640, 480, 525.0, 520.0, 319.5, 239.5};
  const sogmm::Camera d = sogmm::decimated(c, 5);
  expect_camera(d, {128, 96, 105.0, 104.0, 63.9, 47.9});
  const sogmm::Camera odd = sogmm::decimated(sogmm::Camera{643, 481, 500, 500, 321, 240}, 5);
  EXPECT_EQ(odd.width, 128);
  EXPECT_EQ(odd.height, 96);
  const sogmm::Camera same = sogmm::decimated(c, 1);
  EXPECT_EQ(same.width, 640);
  EXPECT_DOUBLE_EQ(same.cx, 319.5);
}

TEST(Camera, BackprojectDecimatedMatchesOpenCvResize) {
  // 640x480 frame with varying depth (some invalid) and a unique gray per
  // pixel; decimate by 5 with OpenCV, back-project by the formula with the
  // decimated intrinsics, compare with backproject().
  const int w = 640, h = 480, d = 5;
  cv::Mat depth(h, w, CV_16U), gray(h, w, CV_32F);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      depth.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>((u * 7 + v * 13) % 3500);  // 0..3.499 m
      gray.at<float>(v, u) = static_cast<float>(v * w + u) / (w * h);
    }
  const sogmm::Camera cam{w, h, 525.0, 525.0, 319.5, 239.5};
  sogmm::RgbdView view{depth.ptr<std::uint16_t>(), gray.ptr<float>(), cam};
  sogmm::DepthOptions opt;
  opt.decimate = d;
  const sogmm::PointCloud pc = sogmm::backproject(view, opt);
  const std::vector<std::int32_t> idx = sogmm::valid_pixel_indices(view, opt);

  cv::Mat dd, gd;
  cv::resize(depth, dd, cv::Size(w / d, h / d), 0, 0, cv::INTER_NEAREST);
  cv::resize(gray, gd, cv::Size(w / d, h / d), 0, 0, cv::INTER_NEAREST);
  const double fx = 525.0 / d, fy = 525.0 / d, cx = 319.5 / d, cy = 239.5 / d;
  std::vector<float> expected;
  std::vector<std::int32_t> expected_idx;
  for (int v = 0; v < h / d; ++v)
    for (int u = 0; u < w / d; ++u) {
      const double z = dd.at<std::uint16_t>(v, u) / 1000.0;
      if (!(z > 0.1 && z <= 3.0)) continue;
      expected.insert(expected.end(), {static_cast<float>((u - cx) * z / fx), static_cast<float>((v - cy) * z / fy),
                                       static_cast<float>(z), gd.at<float>(v, u)});
      expected_idx.push_back(v * (w / d) + u);
    }
  ASSERT_EQ(pc.size(), expected.size() / 4);
  ASSERT_GT(pc.size(), 8000u);
  EXPECT_EQ(idx, expected_idx);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (i % 4 == 3) {
      ASSERT_EQ(pc.xyzg[i], expected[i]) << "gray of point " << i / 4 << " comes from another pixel";
    } else {
      ASSERT_NEAR(pc.xyzg[i], expected[i], 1e-6 * std::max(1.0f, std::fabs(expected[i]))) << "point " << i / 4;
    }
  }
}

TEST(Camera, BackprojectHandComputedPixels) {
  // 4x3 image, fx = 2, fy = 4, cx = 1.5, cy = 1, depth_scale 1000.
  const std::uint16_t depth[12] = {0, 1000, 0, 0,  //
                                   0, 0, 0, 2000,  //
                                   500, 0, 0, 0};
  const float gray[12] = {0, 0.25f, 0, 0, 0, 0, 0, 0.75f, 0.5f, 0, 0, 0};
  sogmm::RgbdView view{depth, gray, sogmm::Camera{4, 3, 2.0, 4.0, 1.5, 1.0}};
  const sogmm::PointCloud pc = sogmm::backproject(view, sogmm::DepthOptions{});
  // (u,v)=(1,0), z=1: x = (1-1.5)/2 = -0.25, y = (0-1)/4 = -0.25
  // (3,1), z=2: x = (3-1.5)*2/2 = 1.5, y = 0
  // (0,2), z=0.5: x = -1.5*0.5/2 = -0.375, y = 1*0.5/4 = 0.125
  const std::vector<float> e = {-0.25f, -0.25f, 1.0f, 0.25f, 1.5f, 0.0f, 2.0f, 0.75f, -0.375f, 0.125f, 0.5f, 0.5f};
  ASSERT_EQ(pc.xyzg.size(), e.size());
  for (std::size_t i = 0; i < e.size(); ++i) EXPECT_NEAR(pc.xyzg[i], e[i], 1e-7) << i;
  EXPECT_EQ(sogmm::valid_pixel_indices(view, sogmm::DepthOptions{}), std::vector<std::int32_t>({1, 7, 8}));
}

TEST(Camera, DepthRangeEdges) {
  // valid iff 0.1 < depth <= 3.0 (m): 100 and 3001 excluded, 101 and 3000 kept.
  const std::uint16_t depth[6] = {0, 100, 101, 3000, 3001, 65535};
  const float gray[6] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  sogmm::RgbdView view{depth, gray, sogmm::Camera{6, 1, 1.0, 1.0, 0.0, 0.0}};
  EXPECT_EQ(sogmm::valid_pixel_indices(view, sogmm::DepthOptions{}), std::vector<std::int32_t>({2, 3}));
  const sogmm::PointCloud pc = sogmm::backproject(view, sogmm::DepthOptions{});
  ASSERT_EQ(pc.size(), 2u);
  EXPECT_FLOAT_EQ(pc.xyzg[2], 0.101f);
  EXPECT_FLOAT_EQ(pc.xyzg[6], 3.0f);
  // TUM scale (5000 per metre): 500 = 0.1 m excluded, 501 kept, 15000 = 3 m kept.
  const std::uint16_t tum[4] = {500, 501, 15000, 15001};
  sogmm::RgbdView tv{tum, gray, sogmm::Camera{4, 1, 1.0, 1.0, 0.0, 0.0}};
  sogmm::DepthOptions o;
  o.depth_scale = 5000.0;
  EXPECT_EQ(sogmm::valid_pixel_indices(tv, o), std::vector<std::int32_t>({1, 2}));
  // Custom range.
  o = sogmm::DepthOptions{};
  o.depth_min = 0.0;
  o.depth_max = 0.1;
  EXPECT_EQ(sogmm::valid_pixel_indices(view, o), std::vector<std::int32_t>({1}));
}

TEST(Camera, GrayFromRgb) {
  EXPECT_NEAR(sogmm::gray_from_rgb(255, 0, 0), 0.299, 1e-6);
  EXPECT_NEAR(sogmm::gray_from_rgb(0, 255, 0), 0.587, 1e-6);
  EXPECT_NEAR(sogmm::gray_from_rgb(0, 0, 255), 0.114, 1e-6);
  EXPECT_NEAR(sogmm::gray_from_rgb(255, 255, 255), 1.0, 1e-6);
  EXPECT_EQ(sogmm::gray_from_rgb(0, 0, 0), 0.0f);
  EXPECT_NEAR(sogmm::gray_from_rgb(10, 200, 30), (0.299 * 10 + 0.587 * 200 + 0.114 * 30) / 255.0, 1e-6);
  const std::uint8_t rgb[6] = {255, 0, 0, 10, 200, 30};  // interleaved RGB, 2x1
  const sogmm::GrayImage g = sogmm::gray_from_rgb_image(rgb, 2, 1);
  EXPECT_EQ(g.width, 2);
  EXPECT_EQ(g.height, 1);
  ASSERT_EQ(g.pixels.size(), 2u);
  EXPECT_NEAR(g.pixels[0], 0.299, 1e-6);  // R first, not BGR
  EXPECT_NEAR(g.pixels[1], (0.299 * 10 + 0.587 * 200 + 0.114 * 30) / 255.0, 1e-6);
  const std::uint8_t u8[3] = {0, 51, 255};
  const sogmm::GrayImage h = sogmm::gray_from_u8_image(u8, 3, 1);
  ASSERT_EQ(h.pixels.size(), 3u);
  EXPECT_NEAR(h.pixels[1], 0.2, 1e-7);
  EXPECT_NEAR(h.pixels[2], 1.0, 1e-7);
}

TEST(Camera, ProjectToImageZBuffer) {
  const sogmm::Camera cam{4, 3, 2.0, 2.0, 1.0, 1.0};
  // Pixel = round(f x / z + c).
  const std::vector<float> pts = {
      0.0f, 0.0f, 2.0f, 0.9f,   // -> (1, 1), far
      0.0f, 0.0f, 1.0f, 0.3f,   // -> (1, 1), near: wins
      0.0f, 0.0f, 3.0f, 0.7f,   // -> (1, 1), farther: loses even though last
      1.0f, 0.5f, 2.0f, 0.5f,   // -> (2, 1.5 -> 2)... round(2*1/2+1)=2, round(2*0.5/2+1)=round(1.5)=2
      1.0f, 0.0f, -1.0f, 0.1f,  // behind the camera: ignored
      10.0f, 0.0f, 1.0f, 0.2f,  // outside (u = 21): ignored
  };
  std::vector<float> values;
  for (std::size_t i = 0; i < pts.size() / 4; ++i) values.push_back(pts[4 * i + 3]);
  const std::vector<float> img = sogmm::project_to_image({pts.data(), pts.size() / 4}, values.data(), cam);
  ASSERT_EQ(img.size(), 12u);
  std::vector<float> e(12, -1.0f);
  e[1 * 4 + 1] = 0.3f;
  e[2 * 4 + 2] = 0.5f;
  for (int i = 0; i < 12; ++i) EXPECT_EQ(img[i], e[i]) << "pixel " << i;
  const std::vector<float> img2 = sogmm::project_to_image({pts.data(), 1}, values.data(), cam, -5.0f);
  EXPECT_EQ(img2[0], -5.0f);
  EXPECT_EQ(img2[5], 0.9f);
}

TEST(Camera, ParseOpen3dIntrinsicsColumnMajor) {
  // Column-major: [fx, 0, 0, 0, fy, 0, cx, cy, 1].
  const std::string text =
      R"({"width": 640, "height": 480, "intrinsic_matrix": [500.0, 0, 0, 0, 510.0, 0, 320.5, 240.25, 1]})";
  const sogmm::Camera c = sogmm::parse_intrinsics_json(text);
  expect_camera(c, {640, 480, 500.0, 510.0, 320.5, 240.25});
}

TEST(Camera, ReadIntrinsicsFile) {
  const std::string path = ::testing::TempDir() + "sogmm_intrinsics_test.json";
  {
    std::ofstream f(path);
    f << "{\n\t\"width\" : 320,\n\t\"height\" : 240,\n\t\"intrinsic_matrix\" :\n\t[\n\t\t262.5,\n\t\t0,\n\t\t0,\n\t\t0,"
         "\n\t\t263.0,\n\t\t0,\n\t\t159.5,\n\t\t119.5,\n\t\t1\n\t]\n}\n";
  }
  const sogmm::Camera c = sogmm::read_intrinsics_json(path);
  std::remove(path.c_str());
  expect_camera(c, {320, 240, 262.5, 263.0, 159.5, 119.5});
}
