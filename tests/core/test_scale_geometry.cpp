// Issue 14 (exact at every scale), geometry items: the mode count's cost with
// a far outlier (item 3), gray regression off the surface (item 4) and
// back-projection for a decimation that does not divide the image (item 7),
// PSNR's data range (item 9; the renderer: tests/tools/test_render.cpp).
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/mean_shift.hpp"
#include "sogmm/metrics.hpp"
#include "test_util.hpp"

namespace {

// (range, gray) features of a synthetic 128 x 96 frame: a tilted wall 1.5 to
// 2.6 m away with a box in front of it, gray a smooth pattern plus noise.
std::vector<double> frame_features() {
  sogmm_test::TestRng rng(14);
  std::vector<double> f;
  for (int v = 0; v < 96; ++v)
    for (int u = 0; u < 128; ++u) {
      const double x = (u - 63.5) / 105.0, y = (v - 47.5) / 105.0;
      const bool box = u > 40 && u < 80 && v > 30 && v < 70;
      const double z = box ? 1.2 + 0.001 * rng.normal() : 1.5 + 0.8 * u / 128.0 + 0.3 * v / 96.0 + 0.002 * rng.normal();
      const double gray = box ? 0.8 + 0.01 * rng.normal() : 0.4 + 0.25 * std::sin(u / 9.0) * std::cos(v / 13.0) + 0.02 * rng.normal();
      f.push_back(z * std::sqrt(1.0 + x * x + y * y));
      f.push_back(gray);
    }
  return f;
}

bool has_center(const sogmm::MeanShiftResult& r, double x, double y) {
  for (std::size_t i = 0; i < r.size(); ++i)
    if (r.centers[2 * i] == x && r.centers[2 * i + 1] == y) return true;
  return false;
}

}  // namespace

// Item 3: the flat mean shift's cost (neighbour checks, independent of the
// clock and the thread count) grows by at most 1.5x when one point 1 km away
// is added; the other modes are unchanged bit for bit and the outlier is one
// extra mode, at its own coordinates to rounding. (The dense grid's cell grew to extent / 1024 = 1 m, 50 x the
// bandwidth, and the cost by about 2500x.)
TEST(ScaleGeometry, ModeCountCostIgnoresAFarOutlier) {
  const std::vector<double> f = frame_features();
  std::vector<double> g = f;
  g.insert(g.end(), {1000.0, 0.5});
  const sogmm::MeanShiftResult base = sogmm::mean_shift_flat(f, 0.02);
  const sogmm::MeanShiftResult far = sogmm::mean_shift_flat(g, 0.02);
  ASSERT_GT(base.neighbour_checks, 0u);
  EXPECT_LE(static_cast<double>(far.neighbour_checks), 1.5 * static_cast<double>(base.neighbour_checks))
      << base.neighbour_checks << " checks without the outlier, " << far.neighbour_checks << " with it";
  ASSERT_EQ(far.size(), base.size() + 1);
  for (std::size_t i = 0; i < base.size(); ++i)
    EXPECT_TRUE(has_center(far, base.centers[2 * i], base.centers[2 * i + 1])) << "mode " << i << " moved";
  // The outlier's mode is the outlier, to rounding: its cell enters the sums
  // whole, as a difference of its row's running sums (row_sum_grid.hpp).
  std::size_t at_outlier = 0;
  for (std::size_t i = 0; i < far.size(); ++i)
    at_outlier += std::fabs(far.centers[2 * i] - 1000.0) <= 1e-9 && std::fabs(far.centers[2 * i + 1] - 0.5) <= 1e-12;
  EXPECT_EQ(at_outlier, 1u) << "the outlier is its own mode";
}

TEST(ScaleGeometry, BlurringModeCountCostIgnoresAFarOutlier) {
  std::vector<double> f = frame_features();
  f.resize(2 * 3000);  // the blurring variant is O(iterations N neighbours): a part of the frame
  std::vector<double> g = f;
  g.insert(g.end(), {1000.0, 0.5});
  const sogmm::MeanShiftResult base = sogmm::mean_shift_gaussian_blurring(f, 0.02, 20);
  const sogmm::MeanShiftResult far = sogmm::mean_shift_gaussian_blurring(g, 0.02, 20);
  EXPECT_LE(static_cast<double>(far.neighbour_checks), 1.5 * static_cast<double>(base.neighbour_checks));
  EXPECT_EQ(far.size(), base.size() + 1);
}

// The sparse grid visits cells and points in a fixed order, and every sum is
// taken in point order, so both mode counters give the same result bit for
// bit on 1, 2 and 3 threads (the blurring one's stop test included).
TEST(ScaleGeometry, ModeCountIsIndependentOfTheThreadCount) {
  std::vector<double> f = frame_features();
  f.insert(f.end(), {1000.0, 0.5});
  std::vector<double> part = frame_features();
  part.resize(2 * 3000);
  const int saved = omp_get_max_threads();
  std::vector<sogmm::MeanShiftResult> r, blurred;
  for (int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    r.push_back(sogmm::mean_shift_flat(f, 0.02));
    blurred.push_back(sogmm::mean_shift_gaussian_blurring(part, 0.02, 20));
  }
  omp_set_num_threads(saved);
  for (int t = 1; t < 3; ++t) {
    EXPECT_EQ(blurred[t].centers, blurred[0].centers) << t + 1 << " threads (blurring)";
    EXPECT_EQ(blurred[t].strengths, blurred[0].strengths) << t + 1 << " threads (blurring)";
    EXPECT_EQ(blurred[t].neighbour_checks, blurred[0].neighbour_checks) << t + 1 << " threads (blurring)";
  }
  for (int t = 1; t < 3; ++t) {
    EXPECT_EQ(r[t].centers, r[0].centers) << t + 1 << " threads";
    EXPECT_EQ(r[t].strengths, r[0].strengths) << t + 1 << " threads";
    EXPECT_EQ(r[t].neighbour_checks, r[0].neighbour_checks) << t + 1 << " threads";
  }
}

// ---------------------------------------------------------------------------
// Item 4: gray regression off the surface. A wall at z = 2 m: 3 x 3
// components 10 cm apart, thin along z, gray means 0.15 to 0.95, with a
// gray-position covariance (so each component's regression line has a slope).
namespace {

sogmm::Gmm wall_model() {
  sogmm::Gmm g;
  g.resize(9);
  const double gray[9] = {0.15, 0.3, 0.95, 0.5, 0.7, 0.2, 0.85, 0.4, 0.6};
  double total = 0.0;
  for (int k = 0; k < 9; ++k) total += 1.0 + k;
  for (int k = 0; k < 9; ++k) {
    Eigen::Matrix4d c = Eigen::Matrix4d::Zero();
    c.diagonal() << 0.04 * 0.04, 0.035 * 0.035, 0.005 * 0.005, 0.01 + 0.001 * k;
    c(3, 0) = c(0, 3) = (k % 2 ? 1.0 : -1.0) * 0.0008;  // correlation 0.2
    c(3, 2) = c(2, 3) = 0.00005;                         // and a slope along the wall's normal
    sogmm_test::set_component(g, k, (1.0 + k) / total,
                              Eigen::Vector4d(0.1 * (k % 3) - 0.1, 0.1 * (k / 3) - 0.1, 2.0, gray[k]), c);
  }
  return g;
}

// The mixture's prior gray and total gray variance, in closed form.
void prior_of(const sogmm::Gmm& g, double& mean, double& variance) {
  double w = 0.0;
  mean = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    w += g.weights[k];
    mean += g.weights[k] * g.means[4 * k + 3];
  }
  mean /= w;
  variance = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double d = g.means[4 * k + 3] - mean;
    variance += g.weights[k] * (g.covariances[16 * k + 15] + d * d);
  }
  variance /= w;
}

// The paper's regression (the rule before issue 14), written out in Eigen:
// weights pi_m N(x), lambda_m = mu_g + S_gx S_xx^-1 (x - mu), variance as the
// second moment minus the squared mean.
void paper_regression(const sogmm::Gmm& g, const Eigen::Vector3d& x, double& mean, double& variance) {
  std::vector<double> lw(g.size()), lambda(g.size()), nu2(g.size());
  for (std::size_t k = 0; k < g.size(); ++k) {
    const Eigen::Matrix4d c = sogmm_test::cov_of(g, k);
    const Eigen::Vector4d mu = sogmm_test::mean_of(g, k);
    const Eigen::Matrix3d sxx = c.topLeftCorner<3, 3>();
    const Eigen::Vector3d sxg = c.block<3, 1>(0, 3);
    const Eigen::Vector3d d = x - mu.head<3>();
    lw[k] = std::log(g.weights[k]) - 0.5 * d.dot(sxx.ldlt().solve(d)) - 0.5 * std::log(sxx.determinant());
    lambda[k] = mu(3) + sxg.dot(sxx.ldlt().solve(d));
    nu2[k] = c(3, 3) - sxg.dot(sxx.ldlt().solve(sxg));
  }
  const double mx = *std::max_element(lw.begin(), lw.end());
  double s = 0.0, m1 = 0.0, m2 = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double e = std::exp(lw[k] - mx);
    s += e;
    m1 += e * lambda[k];
    m2 += e * (nu2[k] + lambda[k] * lambda[k]);
  }
  mean = m1 / s;
  variance = m2 / s - mean * mean;
}

}  // namespace

TEST(ScaleGeometry, RegressionOnTheSurfaceIsThePapers) {
  const sogmm::Gmm g = wall_model();
  sogmm_test::TestRng rng(7);
  std::vector<float> xyz;
  for (int i = 0; i < 200; ++i)  // on the wall, within 2 sigma of its thickness
    xyz.insert(xyz.end(), {static_cast<float>(-0.15 + 0.3 * rng.uniform()), static_cast<float>(-0.15 + 0.3 * rng.uniform()),
                           static_cast<float>(2.0 + 0.01 * (rng.uniform() - 0.5))});
  std::vector<float> mean(200), var(200);
  sogmm::regress_gray(g, xyz.data(), 200, mean.data(), var.data());
  for (int i = 0; i < 200; ++i) {
    double m, v;
    paper_regression(g, Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), m, v);
    EXPECT_NEAR(mean[i], m, 1e-6) << "point " << i;
    EXPECT_NEAR(var[i], v, 1e-6) << "point " << i;
  }
}

// Far from the surface (5 m, 100 m, 3e7 m, in 200 seeded directions and down
// the optical axis) the answer is the prior's gray and variance, inside the
// range of the component gray means (the paper's rule gave -1.5 at 5 m, -143
// to 111 at 100 m, and variance exactly 0 at 3e7 m).
TEST(ScaleGeometry, RegressionFarFromTheSurfaceIsThePrior) {
  const sogmm::Gmm g = wall_model();
  double prior_mean, prior_var;
  prior_of(g, prior_mean, prior_var);
  double lo = 1.0, hi = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) lo = std::min<double>(lo, g.means[4 * k + 3]), hi = std::max<double>(hi, g.means[4 * k + 3]);
  sogmm_test::TestRng rng(11);
  for (double distance : {5.0, 100.0, 3e7}) {
    std::vector<float> xyz = {0.0f, 0.0f, static_cast<float>(2.0 + distance)};
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d dir = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
      for (int j = 0; j < 3; ++j) xyz.push_back(static_cast<float>((j == 2 ? 2.0 : 0.0) + distance * dir(j)));
    }
    const std::size_t n = xyz.size() / 3;
    std::vector<float> mean(n), var(n);
    sogmm::regress_gray(g, xyz.data(), n, mean.data(), var.data());
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_GE(mean[i], lo) << distance << " m, point " << i;
      EXPECT_LE(mean[i], hi) << distance << " m, point " << i;
      EXPECT_NEAR(mean[i], prior_mean, 1e-6) << distance << " m, point " << i;
      EXPECT_NEAR(var[i], prior_var, 1e-6 * prior_var) << distance << " m, point " << i;
    }
  }
}

// Between the two the answer moves continuously: along the normal from the
// wall out to 1 m in 0.5 mm steps, no step changes the mean by more than
// 0.02 or leaves [min, max] of the gray means by more than the components'
// own spread (3 gray standard deviations).
TEST(ScaleGeometry, RegressionFallsBackSmoothly) {
  const sogmm::Gmm g = wall_model();
  std::vector<float> xyz;
  for (int i = 0; i <= 2000; ++i) xyz.insert(xyz.end(), {0.03f, -0.02f, static_cast<float>(2.0 + 0.0005 * i)});
  std::vector<float> mean(2001), var(2001);
  sogmm::regress_gray(g, xyz.data(), 2001, mean.data(), var.data());
  double prior_mean, prior_var;
  prior_of(g, prior_mean, prior_var);
  for (int i = 1; i <= 2000; ++i) {
    EXPECT_LT(std::fabs(mean[i] - mean[i - 1]), 0.02) << "at " << 0.0005 * i << " m";
    EXPECT_GT(mean[i], 0.15 - 3 * 0.11) << "at " << 0.0005 * i << " m";
    EXPECT_LT(mean[i], 0.95 + 3 * 0.11) << "at " << 0.0005 * i << " m";
    EXPECT_GT(var[i], 0.0f);
  }
  EXPECT_NEAR(mean[2000], prior_mean, 1e-6);
}

// ---------------------------------------------------------------------------
// Item 7: d = 7 on 640 x 480 (7 divides neither side). The gray of each pixel
// encodes its index, so each point names the source pixel its depth was read
// from; the point must lie on that pixel's ray of the full-size camera.
TEST(ScaleGeometry, BackprojectionLiesOnTheRayOfItsPixelForAnyDecimation) {
  const int w = 640, h = 480;
  std::vector<std::uint16_t> depth(w * h);
  std::vector<float> gray(w * h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      depth[v * w + u] = static_cast<std::uint16_t>(500 + (u * 7 + v * 13) % 2500);  // 0.5 to 3 m
      gray[v * w + u] = static_cast<float>(v * w + u) / (w * h);  // exact in float: index < 2^19
    }
  const sogmm::Camera cam{w, h, 525.0, 520.0, 319.5, 239.5};
  for (int d : {1, 3, 5, 7, 9, 13}) {
    sogmm::DepthOptions opt;
    opt.decimate = d;
    const sogmm::PointCloud pc = sogmm::backproject(sogmm::RgbdView{depth.data(), gray.data(), cam}, opt);
    ASSERT_EQ(pc.size(), static_cast<std::size_t>((w / d) * (h / d))) << "d = " << d;
    double worst = 0.0;
    for (std::size_t i = 0; i < pc.size(); ++i) {
      const float* p = pc.view()[i];
      const long index = std::lround(static_cast<double>(p[3]) * (w * h));
      const int su = static_cast<int>(index % w), sv = static_cast<int>(index / w);
      EXPECT_EQ(su % d, 0) << "d = " << d << ", point " << i;
      EXPECT_EQ(sv % d, 0) << "d = " << d << ", point " << i;
      EXPECT_NEAR(p[2], depth[index] / 1000.0, 1e-6) << "depth of another pixel";
      const Eigen::Vector3d ray = Eigen::Vector3d((su - cam.cx) / cam.fx, (sv - cam.cy) / cam.fy, 1.0).normalized();
      const Eigen::Vector3d x(p[0], p[1], p[2]);
      worst = std::max(worst, (x - x.dot(ray) * ray).norm());
    }
    EXPECT_LT(worst, 2e-6) << "d = " << d << ": a point lies " << worst << " m from the ray of its pixel";
  }
}

TEST(ScaleGeometry, DecimationConventionIsDocumentedExample) {
  // 7 x 5 image, d = 3: 2 x 1 decimated pixels read source pixels (0, 0) and (3, 0).
  std::vector<std::uint16_t> depth(35, 0);
  std::vector<float> gray(35, 0.0f);
  depth[0] = 1000, depth[3] = 2000, depth[4] = 3000;
  gray[0] = 0.25f, gray[3] = 0.75f, gray[4] = 0.5f;
  const sogmm::Camera cam{7, 5, 3.0, 3.0, 3.0, 0.0};
  sogmm::DepthOptions opt;
  opt.decimate = 3;
  const sogmm::PointCloud pc = sogmm::backproject(sogmm::RgbdView{depth.data(), gray.data(), cam}, opt);
  ASSERT_EQ(pc.size(), 2u);
  // Pixel 0: x = (0 - 3) * 1 / 3 = -1; pixel 3: x = (3 - 3) * 2 / 3 = 0 (decimated: (1 - 1) * 2 / 1).
  EXPECT_FLOAT_EQ(pc.xyzg[0], -1.0f);
  EXPECT_FLOAT_EQ(pc.xyzg[3], 0.25f);
  EXPECT_FLOAT_EQ(pc.xyzg[4], 0.0f);
  EXPECT_FLOAT_EQ(pc.xyzg[6], 2.0f);
  EXPECT_FLOAT_EQ(pc.xyzg[7], 0.75f);
}

// ---------------------------------------------------------------------------
// Item 9: PSNR's data range is a parameter of the honest figure; the
// paper-compatible one keeps the authors' fixed range 2.
TEST(ScaleGeometry, PsnrDataRangeIsAParameter) {
  const float truth[4] = {0.5f, 0.2f, -1.0f, 0.8f};
  const float est[4] = {0.6f, 0.2f, -1.0f, 0.8f};
  const double d = static_cast<double>(0.6f) - static_cast<double>(0.5f);
  const double mse = d * d / 3.0;
  const double paper = 10.0 * std::log10(4.0 / (d * d / 4.0));
  const sogmm::PsnrResult one = sogmm::psnr_images(truth, est, 4);  // default: gray in [0, 1]
  EXPECT_EQ(one.data_range, 1.0);
  EXPECT_NEAR(one.psnr, 10.0 * std::log10(1.0 / mse), 1e-9);
  const sogmm::PsnrResult two = sogmm::psnr_images(truth, est, 4, 2.0);
  EXPECT_NEAR(two.psnr, 10.0 * std::log10(4.0 / mse), 1e-9);  // +6.02 dB
  const double actual = static_cast<double>(0.8f) - static_cast<double>(0.2f);  // 0 = measured: max - min of valid truth
  const sogmm::PsnrResult measured = sogmm::psnr_images(truth, est, 4, 0.0);
  EXPECT_NEAR(measured.data_range, actual, 1e-12);
  EXPECT_NEAR(measured.psnr, 10.0 * std::log10(actual * actual / mse), 1e-9);
  for (const sogmm::PsnrResult& r : {one, two, measured}) EXPECT_NEAR(r.psnr_paper, paper, 1e-9);
  sogmm_test::expect_error([&] { sogmm::psnr_images(truth, est, 4, -1.0); }, sogmm::ErrorCode::InvalidArgument,
                           {"data range"}, "negative data range");
  sogmm_test::expect_error([&] { sogmm::psnr_images(truth, est, 4, NAN); }, sogmm::ErrorCode::InvalidArgument,
                           {"data range"}, "NaN data range");
  const float flat[2] = {0.5f, 0.5f}, off[2] = {0.5f, 0.4f};
  sogmm_test::expect_error([&] { sogmm::psnr_images(flat, off, 2, 0.0); }, sogmm::ErrorCode::InvalidData,
                           {"constant"}, "measured range of a constant image");
  EXPECT_TRUE(std::isinf(sogmm::psnr_images(flat, flat, 2, 0.0).psnr));
}
