// Bad input: sogmm::Error with the right code and a message naming the
// problem; never a crash, hang or NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/em.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/mean_shift.hpp"
#include "sogmm/point_cloud.hpp"
#include "test_util.hpp"

using sogmm::ErrorCode;
using sogmm_test::expect_error;

namespace {
std::vector<float> small_cloud(std::size_t n = 50) {
  sogmm_test::TestRng r(1);
  std::vector<float> p;
  for (std::size_t i = 0; i < n; ++i)
    p.insert(p.end(), {static_cast<float>(0.1 * r.normal()), static_cast<float>(0.1 * r.normal()),
                       static_cast<float>(1.0 + 0.1 * r.normal()), static_cast<float>(r.uniform())});
  return p;
}
const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();
}  // namespace

TEST(BadInput, AllInvalidDepthGivesEmptyCloudThatFitRejects) {
  const std::vector<std::uint16_t> depth(64 * 48, 0);  // no readings
  const std::vector<float> gray(64 * 48, 0.5f);
  sogmm::RgbdView view{depth.data(), gray.data(), sogmm::Camera{64, 48, 50, 50, 32, 24}};
  // backproject() documents returning the valid pixels: none here. Whatever it
  // does, it must not crash, and a fit of the result must be a clear error.
  sogmm::PointCloud pc;
  try {
    pc = sogmm::backproject(view, sogmm::DepthOptions{});
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidData) << e.what();
    return;
  }
  EXPECT_EQ(pc.size(), 0u);
  expect_error([&] { sogmm::fit(pc.view(), sogmm::FitOptions{}); }, ErrorCode::InvalidData,
               {"empty", "no point", "0 point", "no valid"}, "fit of an all-invalid frame");
  // Depth entirely out of range (all 5 m) is the same case.
  const std::vector<std::uint16_t> far(64 * 48, 5000);
  view.depth = far.data();
  EXPECT_EQ(sogmm::valid_pixel_indices(view, sogmm::DepthOptions{}).size(), 0u);
}

TEST(BadInput, EmptyCloud) {
  const sogmm::PointsView empty{nullptr, 0};
  expect_error([&] { sogmm::fit(empty, sogmm::FitOptions{}); }, ErrorCode::InvalidData, {"empty", "no point", "0 point"},
               "fit of an empty cloud");
  expect_error([&] { sogmm::fit_em(empty, {0}, sogmm::EmOptions{}); }, ErrorCode::InvalidData,
               {"empty", "no point", "0 point"}, "fit_em of an empty cloud");
  expect_error([&] { sogmm::require_finite_points(empty, "my cloud"); }, ErrorCode::InvalidData, {"empty", "my cloud"},
               "require_finite_points of an empty cloud");
  expect_error([&] { sogmm::mean_shift_flat({}, 0.02); }, ErrorCode::InvalidData, {"empty", "no point", "0 point"},
               "mean shift on no data");
}

TEST(BadInput, EmptyOrInvalidCamera) {
  const std::uint16_t depth[1] = {1000};
  const float gray[1] = {0.5f};
  expect_error([&] { sogmm::backproject({depth, gray, sogmm::Camera{0, 0, 1, 1, 0, 0}}, {}); },
               ErrorCode::InvalidArgument, {"width", "height", "size"}, "0x0 camera");
  expect_error([&] { sogmm::backproject({depth, gray, sogmm::Camera{1, 1, 0, 1, 0, 0}}, {}); },
               ErrorCode::InvalidArgument, {"fx", "focal"}, "fx = 0");
  expect_error([&] { sogmm::validate(sogmm::Camera{1, 1, 1, std::nan(""), 0, 0}); }, ErrorCode::InvalidArgument,
               {"fy", "finite", "nan"}, "fy = NaN");
  sogmm::DepthOptions o;
  o.decimate = 0;
  expect_error([&] { sogmm::backproject({depth, gray, sogmm::Camera{1, 1, 1, 1, 0, 0}}, o); },
               ErrorCode::InvalidArgument, {"decimat"}, "decimate = 0");
  o = {};
  o.depth_scale = 0;
  expect_error([&] { sogmm::validate(o); }, ErrorCode::InvalidArgument, {"scale"}, "depth_scale = 0");
  o = {};
  o.depth_min = 3.0;
  o.depth_max = 1.0;
  expect_error([&] { sogmm::validate(o); }, ErrorCode::InvalidArgument, {"depth_min", "depth_max", "min", "range"},
               "depth_min > depth_max");
}

TEST(BadInput, NaNAndInfInCloud) {
  for (float bad : {kNaN, kInf, -kInf}) {
    std::vector<float> p = small_cloud();
    p[4 * 17 + 2] = bad;
    const sogmm::PointsView v{p.data(), p.size() / 4};
    expect_error([&] { sogmm::require_finite_points(v, "cloud"); }, ErrorCode::InvalidData, {"17"},
                 "require_finite_points names the bad point");
    expect_error([&] { sogmm::fit(v, sogmm::FitOptions{}); }, ErrorCode::InvalidData,
                 {"finite", "nan", "inf"}, "fit with a non-finite point");
    sogmm::FitOptions k;
    k.n_components = 3;
    expect_error([&] { sogmm::fit(v, k); }, ErrorCode::InvalidData, {"finite", "nan", "inf"},
                 "fixed-K fit with a non-finite point");
    expect_error([&] { sogmm::fit_em(v, {0, 1, 2}, sogmm::EmOptions{}); }, ErrorCode::InvalidData,
                 {"finite", "nan", "inf"}, "fit_em with a non-finite point");
    expect_error([&] { sogmm::kmeanspp_seeds(v, 3, 0); }, ErrorCode::InvalidData, {"finite", "nan", "inf"},
                 "kmeanspp with a non-finite point");
    std::vector<double> two = {0.1, 0.2, 0.3, static_cast<double>(bad)};
    expect_error([&] { sogmm::mean_shift_flat(two, 0.1); }, ErrorCode::InvalidData, {"finite", "nan", "inf"},
                 "mean shift with a non-finite value");
  }
}

TEST(BadInput, NonFiniteQueryPoints) {
  sogmm::Gmm g;
  g.resize(1);
  sogmm_test::set_component(g, 0, 1.0, Eigen::Vector4d(0, 0, 1, 0.5), 0.01 * Eigen::Matrix4d::Identity());
  const float x[8] = {0, 0, 1, 0.5f, 0, kNaN, 1, 0.5f};
  double out[2];
  expect_error([&] { sogmm::score_samples(g, x, 2, 4, out); }, ErrorCode::InvalidData, {"finite", "nan", "inf"},
               "score_samples with NaN");
  expect_error([&] { sogmm::score_samples(g, x, 2, 2, out); }, ErrorCode::InvalidArgument, {"dim"},
               "score_samples with dims = 2");
  sogmm::Gmm broken = g;
  broken.covariances[0] = -1.0f;  // not positive definite
  const float ok[4] = {0, 0, 1, 0.5f};
  expect_error([&] { sogmm::score_samples(broken, ok, 1, 4, out); }, ErrorCode::Numeric,
               {"positive", "cholesky", "covariance", "invalid"}, "score_samples with an invalid model");
}

TEST(BadInput, BandwidthNotPositive) {
  const std::vector<float> p = small_cloud();
  const sogmm::PointsView v{p.data(), p.size() / 4};
  for (double h : {0.0, -0.02, std::nan(""), std::numeric_limits<double>::infinity()}) {
    sogmm::FitOptions o;
    o.bandwidth = h;
    expect_error([&] { sogmm::fit(v, o); }, ErrorCode::InvalidArgument, {"bandwidth"}, "fit with a bad bandwidth");
    expect_error([&] { sogmm::mean_shift_flat({0.1, 0.2, 0.3, 0.4}, h); }, ErrorCode::InvalidArgument,
                 {"bandwidth"}, "mean shift with a bad bandwidth");
  }
}

TEST(BadInput, ComponentCountOutOfRange) {
  const std::vector<float> p = small_cloud(50);
  const sogmm::PointsView v{p.data(), 50};
  expect_error([&] { sogmm::kmeanspp_seeds(v, 0, 0); }, ErrorCode::InvalidArgument, {"component", "k =", "k=", " k ", "number of seeds"},
               "k-means++ with K = 0");
  expect_error([&] { sogmm::kmeanspp_seeds(v, 51, 0); }, ErrorCode::InvalidArgument, {"component", "k =", "k=", " k ", "number of seeds"},
               "k-means++ with K > N");
  sogmm::FitOptions o;
  o.n_components = 51;
  expect_error([&] { sogmm::fit(v, o); }, ErrorCode::InvalidArgument, {"component", "k =", "k=", " k "}, "fixed-K fit with K > N");
  expect_error([&] { sogmm::fit_em(v, {}, sogmm::EmOptions{}); }, ErrorCode::InvalidArgument,
               {"seed", "component"}, "fit_em with no seeds");
  expect_error([&] { sogmm::fit_em(v, {0, 50}, sogmm::EmOptions{}); }, ErrorCode::InvalidArgument,
               {"seed", "index", "range"}, "fit_em with a seed index out of range");
}

TEST(BadInput, EmOptionsOutOfRange) {
  const std::vector<float> p = small_cloud(50);
  const sogmm::PointsView v{p.data(), 50};
  sogmm::EmOptions o;
  o.reg_covar = -1e-6;
  expect_error([&] { sogmm::fit_em(v, {0, 1}, o); }, ErrorCode::InvalidArgument, {"reg_covar", "regulari"},
               "negative reg_covar");
  o = {};
  o.tol = std::nan("");
  expect_error([&] { sogmm::fit_em(v, {0, 1}, o); }, ErrorCode::InvalidArgument, {"tol"}, "tol = NaN");
  o = {};
  o.threads = -1;
  expect_error([&] { sogmm::fit_em(v, {0, 1}, o); }, ErrorCode::InvalidArgument, {"thread"}, "threads = -1");
}

TEST(BadInput, IntrinsicsJsonMissingFields) {
  const char* matrix = R"("intrinsic_matrix": [500, 0, 0, 0, 500, 0, 320, 240, 1])";
  expect_error([&] { sogmm::parse_intrinsics_json(std::string("{\"height\": 480, ") + matrix + "}", "cam.json"); },
               ErrorCode::Format, {"width"}, "missing width");
  expect_error([&] { sogmm::parse_intrinsics_json(std::string("{\"width\": 640, ") + matrix + "}"); },
               ErrorCode::Format, {"height"}, "missing height");
  expect_error([&] { sogmm::parse_intrinsics_json(R"({"width": 640, "height": 480})"); }, ErrorCode::Format,
               {"intrinsic_matrix"}, "missing intrinsic_matrix");
  expect_error(
      [&] { sogmm::parse_intrinsics_json(R"({"width": 640, "height": 480, "intrinsic_matrix": [500, 0, 0, 0, 500, 0, 320, 240]})"); },
      ErrorCode::Format, {"intrinsic_matrix", "9"}, "intrinsic_matrix with 8 numbers");
  expect_error(
      [&] { sogmm::parse_intrinsics_json(R"({"width": "wide", "height": 480, "intrinsic_matrix": [500, 0, 0, 0, 500, 0, 320, 240, 1]})"); },
      ErrorCode::Format, {"width"}, "width not a number");
  expect_error([&] { sogmm::parse_intrinsics_json("{\"width\": 640,", "broken.json"); }, ErrorCode::Format,
               {"broken.json", "json", "parse"}, "truncated JSON");
  // An fx of 0 is an invalid field (Format) or an invalid camera (InvalidArgument).
  sogmm_test::expect_error_codes(
      [&] { sogmm::parse_intrinsics_json(R"({"width": 640, "height": 480, "intrinsic_matrix": [0, 0, 0, 0, 500, 0, 320, 240, 1]})"); },
      {ErrorCode::Format, ErrorCode::InvalidArgument}, {"fx", "focal", "intrinsic"}, "fx = 0 in JSON");
}

TEST(BadInput, IntrinsicsFileUnreadable) {
  const std::string path = ::testing::TempDir() + "sogmm_no_such_dir/intrinsics.json";
  expect_error([&] { sogmm::read_intrinsics_json(path); }, ErrorCode::Io, {"sogmm_no_such_dir", "intrinsics.json"},
               "unreadable intrinsics file (message names the path)");
}

TEST(BadInput, DegenerateButLegalInputsGiveValidModels) {
  // Not errors, but must not produce NaN: all points identical (covariances are
  // reg_covar I), and K = N.
  std::vector<float> same;
  for (int i = 0; i < 30; ++i) same.insert(same.end(), {0.5f, 0.5f, 1.0f, 0.3f});
  sogmm::FitOptions o;
  o.bandwidth = 0.02;
  const sogmm::FitResult r = sogmm::fit({same.data(), 30}, o);
  EXPECT_EQ(r.gmm.size(), 1u);
  EXPECT_TRUE(sogmm_test::model_is_valid(r.gmm));
  const std::vector<float> p = small_cloud(12);
  sogmm::FitOptions k;
  k.n_components = 12;
  const sogmm::FitResult rk = sogmm::fit({p.data(), 12}, k);
  EXPECT_EQ(rk.gmm.size(), 12u);
  EXPECT_TRUE(sogmm_test::model_is_valid(rk.gmm));
}

// Images of different sizes cannot be expressed: psnr_images takes one pixel
// count for both images and RgbdView one camera for depth and gray.
