// Depth quantisation (issue 14 item 10): detection, the floor a depth bin puts
// on a component's variance along its ray (hand-computed), and EM on quantised
// depth: plain EM collapses components onto single depth levels, EM with the
// floor does not and is the better density of the surface the sensor saw.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sogmm/depth_quantisation.hpp"
#include "sogmm/em.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/kmeanspp.hpp"
#include "test_util.hpp"

namespace {

sogmm::PointsView view(const std::vector<float>& p) { return {p.data(), p.size() / 4}; }

// Kinect-style disparity quantisation: depth levels 1 / (a - b k), spaced
// 0.0036 z^2 apart (4 mm at 1 m, 14 mm at 2 m, as on the shared frames).
double level_of(double z, double* width) {
  constexpr double c = 0.0036;
  const double k = std::round(1.0 / (c * z));
  if (width) *width = 1.0 / (c * (k - 0.5)) - 1.0 / (c * (k + 0.5));
  return 1.0 / (c * k);
}

// Two tilted planes 1.2 - 2.4 m in front of the camera with a gray gradient;
// `dither` places each point uniformly within its depth bin along its ray
// (the surface the sensor saw), otherwise on its level (what it stored).
std::vector<float> scene(std::uint64_t seed, bool dither) {
  sogmm_test::TestRng r(seed);
  std::vector<float> pts;
  for (int i = 0; i < 6000; ++i) {
    const int plane = i % 2;
    const double u = r.uniform() - 0.5, v = r.uniform() - 0.5;
    const double x = plane ? 0.8 * u : 0.9 * u + 0.2, y = plane ? 0.6 * v : 0.5 * v;
    const double z = plane ? 1.8 + 0.5 * u + 0.3 * v : 1.6 - 0.35 * u + 0.1 * v;
    double w;
    const double zl = level_of(z, &w);
    const double zq = dither ? zl + (r.uniform() - 0.5) * w : zl;
    const double s = zq / z;
    pts.insert(pts.end(), {static_cast<float>(x * s), static_cast<float>(y * s), static_cast<float>(zq),
                           static_cast<float>(0.5 + 0.3 * u + 0.01 * r.normal())});
  }
  return pts;
}

// Components collapsed onto a depth level: variance along the viewing ray at
// the reg_covar floor.
int collapsed_along_the_ray(const sogmm::Gmm& g, double reg_covar) {
  int n = 0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    const Eigen::Matrix3d c = sogmm_test::cov_of(g, k).topLeftCorner<3, 3>();
    const Eigen::Vector3d ray = sogmm_test::mean_of(g, k).head<3>().normalized();
    if (ray.dot(c * ray) < 1.5 * reg_covar) ++n;
  }
  return n;
}

}  // namespace

TEST(DepthQuantisation, DetectsOnlyQuantisedCameraFrameDepth) {
  EXPECT_FALSE(sogmm::DepthQuantisation::detect(view(scene(1, false))).empty());
  // Continuous depths: about one point per distinct value.
  EXPECT_TRUE(sogmm::DepthQuantisation::detect(view(scene(1, true))).empty());
  // A point at or behind the camera: not a camera-frame cloud.
  std::vector<float> behind = scene(1, false);
  behind[2] = -1.0f;
  EXPECT_TRUE(sogmm::DepthQuantisation::detect(view(behind)).empty());
}

TEST(DepthQuantisation, FloorsTheVarianceAlongTheRay) {
  // Levels 1.00, 1.01, 1.03 (8 points each); a mean at z = 1.02 lies in the
  // bin 1.01 - 1.03: w = 0.02, v = (0.51 / 1.02, -0.204 / 1.02, 1) = (0.5, -0.2, 1).
  std::vector<float> pts;
  for (float z : {1.00f, 1.01f, 1.03f})
    for (int i = 0; i < 8; ++i) pts.insert(pts.end(), {0.f, 0.f, z, 0.5f});
  const sogmm::DepthQuantisation q = sogmm::DepthQuantisation::detect(view(pts));
  ASSERT_FALSE(q.empty());
  double cov[16] = {};
  const double mean[4] = {0.51, -0.204, 1.02, 0.3};
  q.floor_covariance_at(mean, cov);
  const double w = static_cast<double>(1.03f) - static_cast<double>(1.01f), s = w * w / 12.0;
  const double v[4] = {0.5, -0.2, 1.0, 0.0};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) EXPECT_NEAR(cov[4 * a + b], s * v[a] * v[b], 1e-15) << a << "," << b;
  // A component already wider along the ray than the bin is left alone; a
  // narrower one gains exactly what it lacks along the ray.
  const double norm = std::sqrt(1.0 + 0.25 + 0.04), u[3] = {0.5 / norm, -0.2 / norm, 1.0 / norm};
  const double bin = s * norm * norm;
  for (double a : {2.0 * bin, 0.25 * bin}) {
    double c[16] = {};
    for (int i = 0; i < 4; ++i) c[5 * i] = a;
    q.floor_covariance_at(mean, c);
    const double gain = std::max(0.0, bin - a);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(c[4 * i + j], (i == j ? a : 0.0) + gain * u[i] * u[j], 1e-15);
    EXPECT_EQ(c[15], a);
  }
  // Beyond the outermost level: the nearest spacing.
  double far[16] = {};
  const double beyond[4] = {0.0, 0.0, 2.0, 0.3};
  q.floor_covariance_at(beyond, far);
  EXPECT_NEAR(far[10], s, 1e-15);
}

TEST(DepthQuantisation, LevelsAreSortedWhateverThePointOrder) {
  // The levels 0.25, 1.00, 1.01, 1.03 and 4.0 (8 points each, in a rotating
  // order, so the input is neither sorted nor grouped; 0.25 and 4.0 differ
  // from the others in the float's exponent): a mean at z = 1.02 lies in the
  // bin 1.01 - 1.03 only if the distinct depths were sorted (detect sorts
  // the float32 bit patterns, which for z > 0 order as the values), so the
  // floor is FloorsTheVarianceAlongTheRay's hand-computed w^2 / 12 along the
  // optical axis. Exact comparisons of one product of doubles: the same on
  // every kernel (no EM kernel runs here).
  const float levels[] = {1.03f, 4.0f, 1.00f, 0.25f, 1.01f};
  std::vector<float> pts;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 5; ++j) pts.insert(pts.end(), {0.f, 0.f, levels[(i + j) % 5], 0.5f});
  const sogmm::DepthQuantisation q = sogmm::DepthQuantisation::detect(view(pts));
  ASSERT_FALSE(q.empty());
  double cov[16] = {};
  const double mean[4] = {0.0, 0.0, 1.02, 0.3};
  q.floor_covariance_at(mean, cov);
  const double w = static_cast<double>(1.03f) - static_cast<double>(1.01f);
  EXPECT_NEAR(cov[10], w * w / 12.0, 1e-15);
  // Beyond the outermost levels: the spacing next to 4.0 (from 1.03), and
  // below 0.25 the spacing from 0.25 to 1.00.
  double far[16] = {}, near[16] = {};
  const double beyond[4] = {0.0, 0.0, 5.0, 0.3}, before[4] = {0.0, 0.0, 0.2, 0.3};
  q.floor_covariance_at(beyond, far);
  q.floor_covariance_at(before, near);
  const double w_far = 4.0 - static_cast<double>(1.03f), w_near = 1.0 - 0.25;
  EXPECT_NEAR(far[10], w_far * w_far / 12.0, 1e-15);
  EXPECT_NEAR(near[10], w_near * w_near / 12.0, 1e-15);
}

TEST(DepthQuantisation, EmWithTheFloorDoesNotCollapseOntoLevels) {
  const std::vector<float> stored = scene(7, false), seen = scene(8, true);
  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(stored), 300, 3);
  sogmm::EmOptions plain;
  sogmm::EmOptions floored;
  floored.quantisation = sogmm::DepthQuantisation::detect(view(stored));
  ASSERT_FALSE(floored.quantisation.empty());
  sogmm::EmReport rp, rd;
  const sogmm::Gmm gp = sogmm::fit_em(view(stored), seeds, plain, &rp);
  const sogmm::Gmm gd = sogmm::fit_em(view(stored), seeds, floored, &rd);
  ASSERT_TRUE(sogmm_test::model_is_valid(gd));
  const int np = collapsed_along_the_ray(gp, rp.reg_covar.spatial), nd = collapsed_along_the_ray(gd, rp.reg_covar.spatial);
  std::printf("plain: %d iterations, %d of 300 collapsed; floored: %d iterations, %d collapsed\n", rp.iterations,
              np, rd.iterations, nd);
  EXPECT_GE(np, 2);  // the scene does collapse plain EM
  EXPECT_EQ(nd, 0);
  EXPECT_TRUE(rd.converged);
  EXPECT_LE(rd.iterations, rp.iterations);
  // On the surface the sensor saw (held out), the floored fit is the better
  // density.
  const double sp = sogmm_test::score(gp, seen), sd = sogmm_test::score(gd, seen);
  std::printf("held-out mean log-likelihood: plain %.4f, floored %.4f\n", sp, sd);
  EXPECT_GT(sd, sp + 0.03);
}

// fit() applies the floor by default to points from a depth image
// (PointsView::from_depth_image), to other points only when asked
// (FitOptions::dequantise_depth), never when told not to; and then exactly as
// fit_em with the detected quantisation does.
TEST(DepthQuantisation, FitAppliesTheFloorToDepthImagesByDefault) {
  const std::vector<float> stored = scene(7, false);
  sogmm::PointsView from_image = view(stored);
  from_image.from_depth_image = true;
  sogmm::FitOptions o;
  o.n_components = 300;
  o.seed = 3;
  o.em.threads = 1;
  ASSERT_EQ(o.dequantise_depth, sogmm::Dequantise::Auto);
  const sogmm::FitResult off = sogmm::fit(view(stored), o);
  const sogmm::FitResult image_default = sogmm::fit(from_image, o);
  o.dequantise_depth = sogmm::Dequantise::On;
  const sogmm::FitResult on = sogmm::fit(view(stored), o);
  o.dequantise_depth = sogmm::Dequantise::Off;
  const sogmm::FitResult image_off = sogmm::fit(from_image, o);
  EXPECT_GE(collapsed_along_the_ray(off.gmm, off.em.reg_covar.spatial), 2);
  EXPECT_EQ(collapsed_along_the_ray(on.gmm, on.em.reg_covar.spatial), 0);
  EXPECT_EQ(image_default.gmm.covariances, on.gmm.covariances);
  EXPECT_EQ(image_off.gmm.covariances, off.gmm.covariances);

  const std::vector<std::size_t> seeds = sogmm::kmeanspp_seeds(view(stored), 300, 3);
  sogmm::EmOptions floored = o.em;
  floored.quantisation = sogmm::DepthQuantisation::detect(view(stored));
  const sogmm::Gmm direct = sogmm::fit_em(view(stored), seeds, floored);
  EXPECT_EQ(direct.means, on.gmm.means);
}
