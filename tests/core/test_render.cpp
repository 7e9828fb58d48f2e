// The renderer (sogmm/render.hpp, issue 29 part 3) against independent
// truth: the closed-form mode and regression of one component along a ray,
// the first-surface rule on a hand-built scene, the surface-evidence rule
// (where a component's surface ends, evidence adding up, a graze), a fitted plane, the
// invariance under moving model and pose together, threads, progress and
// bad input; score_render on a hand-computed case.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/model.hpp"
#include "sogmm/render.hpp"
#include "pose_util.hpp"
#include "test_util.hpp"

namespace {

void set_component(sogmm::Gmm& g, std::size_t k, double w, const Eigen::Vector4d& mu, const Eigen::Matrix4d& cov) {
  g.weights[k] = static_cast<float>(w);
  for (int i = 0; i < 4; ++i) g.means[4 * k + i] = static_cast<float>(mu(i));
  for (int i = 0; i < 16; ++i) g.covariances[16 * k + i] = static_cast<float>(cov(i / 4, i % 4));
}

Eigen::Matrix4d diag(double a, double b, double c, double d) { return Eigen::Vector4d(a, b, c, d).asDiagonal(); }

// A small sparse patch at z = 1 m (one component, weight 0.01, gray 0.2) in
// front of a dense wall at z = 2 m (3 x 3 components, weight 0.99, thinner,
// gray 0.9): along the central ray the wall's density peak is about 16x the
// patch's (checked below with score_samples).
sogmm::Gmm two_surfaces() {
  sogmm::Gmm g;
  g.resize(10);
  set_component(g, 0, 0.01, Eigen::Vector4d(0, 0, 1.0, 0.2), diag(0.03 * 0.03, 0.03 * 0.03, 0.02 * 0.02, 0.001));
  for (int k = 0; k < 9; ++k)
    set_component(g, 1 + k, 0.99 / 9, Eigen::Vector4d(0.2 * (k % 3) - 0.2, 0.2 * (k / 3) - 0.2, 2.0, 0.9),
                  diag(0.1 * 0.1, 0.1 * 0.1, 0.002 * 0.002, 0.001));
  return g;
}

const sogmm::Camera kSmall{9, 9, 20.0, 20.0, 4.0, 4.0};  // pixel u looks along x / z = (u - 4) / 20

std::size_t at(const sogmm::Camera& c, int u, int v) { return static_cast<std::size_t>(v) * c.width + u; }

// One tilted, correlated component (a thin disc with gray correlated with
// position): its full 4x4 covariance, built from a rotation so that it is
// positive definite by construction.
sogmm::Gmm tilted_component(Eigen::Vector4d* mu_out, Eigen::Matrix4d* cov_out) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix();
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  cov.topLeftCorner<3, 3>() = R * Eigen::Vector3d(0.05 * 0.05, 0.03 * 0.03, 0.004 * 0.004).asDiagonal() * R.transpose();
  cov(3, 3) = 0.01;
  cov(3, 0) = cov(0, 3) = 0.3 * 0.05 * 0.1;  // gray rises with x
  cov(3, 1) = cov(1, 3) = -0.2 * 0.03 * 0.1;
  const Eigen::Vector4d mu(0.05, -0.03, 1.4, 0.5);
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, mu, cov);
  *mu_out = mu;
  *cov_out = cov;
  return g;
}

}  // namespace

TEST(Render, SingleComponentModeAndRegressionAreTheClosedForm) {
  Eigen::Vector4d mu;
  Eigen::Matrix4d cov;
  const sogmm::Gmm g = tilted_component(&mu, &cov);
  const sogmm::Camera cam{64, 48, 50.0, 55.0, 31.5, 23.5};
  const sogmm::RenderedImages r = sogmm::render_expected_surface(g, cam);
  ASSERT_EQ(r.depth.size(), 64u * 48u);
  // For one component the ray's density is one Gaussian in t, with its mode
  // at t* = d^T P mu / d^T P d (P = Sigma_xx^-1); gray there is the
  // conditional mean mu_g + S_gx S_xx^-1 (x - mu_x), its variance
  // S_gg - S_gx S_xx^-1 S_xg. Checked at the centre pixel and off-centre.
  const Eigen::Matrix3d S = cov.topLeftCorner<3, 3>();
  const Eigen::Matrix3d P = S.inverse();
  const Eigen::Vector3d sgx = cov.block<1, 3>(3, 0).transpose();
  for (const auto& [u, v] : {std::pair{32, 24}, std::pair{33, 23}, std::pair{31, 25}}) {
    const Eigen::Vector3d d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
    const double t = d.dot(P * mu.head<3>()) / d.dot(P * d);
    const Eigen::Vector3d x = t * d;
    const double gray = mu(3) + sgx.dot(S.ldlt().solve(x - mu.head<3>()));
    const double var = cov(3, 3) - sgx.dot(S.ldlt().solve(sgx));
    SCOPED_TRACE(testing::Message() << "pixel " << u << ", " << v);
    ASSERT_FALSE(std::isnan(r.depth[at(cam, u, v)]));
    EXPECT_NEAR(r.depth[at(cam, u, v)], t, 1e-5 * t);
    EXPECT_NEAR(r.gray[at(cam, u, v)], gray, 1e-5);
    EXPECT_NEAR(r.variance[at(cam, u, v)], var, 1e-6);
  }
  // A corner ray passes far (> 3 sigma) from the disc: empty in all three.
  EXPECT_TRUE(std::isnan(r.depth[0]) && std::isnan(r.gray[0]) && std::isnan(r.variance[0]));
}

TEST(Render, FirstSurfaceAlongTheRayNotTheDensest) {
  const sogmm::Gmm g = two_surfaces();
  // The densest point of the central ray is on the wall, by a factor > 10.
  const float on_ray[6] = {0, 0, 1.0f, 0, 0, 2.0f};
  double log_p[2];
  sogmm::score_samples(g, on_ray, 2, 3, log_p);
  ASSERT_GT(log_p[1], log_p[0] + std::log(10.0));
  const sogmm::RenderedImages r = sogmm::render_expected_surface(g, kSmall);
  // Centre pixel: the ray meets the patch at 1 m, then the wall at 2 m.
  EXPECT_NEAR(r.depth[at(kSmall, 4, 4)], 1.0, 1e-3);
  EXPECT_NEAR(r.gray[at(kSmall, 4, 4)], 0.2, 1e-3);
  // Corner pixel: x / z = 0.2, 6.7 sigma beside the patch at 1 m: only the wall.
  EXPECT_NEAR(r.depth[at(kSmall, 8, 8)], 2.0, 1e-3);
  EXPECT_NEAR(r.gray[at(kSmall, 8, 8)], 0.9, 1e-3);
  // depth_max below the wall: the corner shows nothing, the centre the patch.
  sogmm::RenderOptions near;
  near.depth_max = 1.5;
  const sogmm::RenderedImages n = sogmm::render_expected_surface(g, kSmall, near);
  EXPECT_TRUE(std::isnan(n.depth[at(kSmall, 8, 8)]));
  EXPECT_NEAR(n.depth[at(kSmall, 4, 4)], 1.0, 1e-3);
}

TEST(Render, RemovingTheFrontSurfaceShowsTheOneBehind) {
  sogmm::Gmm g = two_surfaces();
  g.weights[0] = 0.0f;  // the patch no longer exists (and its peak is no surface)
  for (int k = 1; k < 10; ++k) g.weights[k] = 1.0f / 9.0f;
  const sogmm::RenderedImages r = sogmm::render_expected_surface(g, kSmall);
  EXPECT_NEAR(r.depth[at(kSmall, 4, 4)], 2.0, 1e-3);
  EXPECT_NEAR(r.gray[at(kSmall, 4, 4)], 0.9, 1e-3);
}

// The surface-evidence rule (RenderOptions::surface_sigma = 2): a mode is a
// surface only where sum_k exp(-D_k^2 / 2) at its point reaches exp(-2), one
// component at 2 sigma.
// Ground truth from the closed form of one thin disc at z = 1 m (sigma 5 cm
// in x and y, 1 mm in z): a ray of slope s = x / z passes at Mahalanobis
// distance r = s / sqrt(sx^2 + s^2 sz^2) from its mean (the minimum over t of
// t^2 s^2 / sx^2 + (t - 1)^2 / sz^2), and its 1-D mode is that minimiser, so
// D = r there: the pixel shows the disc iff r <= 2.
TEST(Render, AComponentShowsASurfaceOutToTwoSigma) {
  const double sx = 0.05, sz = 0.001;
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, Eigen::Vector4d(0, 0, 1.0, 0.5), diag(sx * sx, sx * sx, sz * sz, 0.01));
  const sogmm::Camera cam{61, 1, 200.0, 200.0, 0.0, 0.0};  // pixel u: slope u / 200, 0 to 0.3
  sogmm::RenderOptions o;
  o.surface_sigma = 2.0;
  const sogmm::RenderedImages r = sogmm::render_expected_surface(g, cam, o);
  const sogmm::RenderedImages every = sogmm::render_expected_surface(g, cam);  // surface_sigma 0
  int shown = 0, hidden = 0;
  for (int u = 0; u < cam.width; ++u) {
    const double s = u / cam.fx, dist = s / std::sqrt(sx * sx + s * s * sz * sz);
    if (std::abs(dist - 2.0) < 0.01) continue;  // at the threshold itself rounding decides
    SCOPED_TRACE(testing::Message() << "pixel " << u << ", ray at " << dist << " sigma");
    if (dist < 2.0) {
      ASSERT_FALSE(std::isnan(r.depth[at(cam, u, 0)]));
      const double t = 1.0 / (1.0 + s * s * sz * sz / (sx * sx));  // the minimiser above
      EXPECT_NEAR(r.depth[at(cam, u, 0)], t, 1e-5);
      ++shown;
    } else {
      EXPECT_TRUE(std::isnan(r.depth[at(cam, u, 0)]));
      EXPECT_EQ(std::isnan(every.depth[at(cam, u, 0)]), dist > 3.0);  // without the rule: out to max_mahalanobis
      ++hidden;
    }
  }
  EXPECT_EQ(shown, 20);   // u = 0..19: r < 1.9
  EXPECT_EQ(hidden, 40);  // u = 21..60 (u = 20 sits on the threshold)
}

// Beside the silhouette of a near patch, a ray 2.5 sigma off the patch's mean
// (evidence exp(-3.125) = 0.044) passes on to the wall behind it; two
// components 2.1 sigma either side of a ray (each 0.110 alone, 0.220
// together) show a surface that neither shows alone.
TEST(Render, EvidenceAddsUpAndAGrazeIsNoSurface) {
  const double s = 0.02, sz = 0.001;
  const sogmm::Camera cam{1, 1, 100.0, 100.0, 0.0, 0.0};  // one ray, along z
  sogmm::Gmm g;
  g.resize(2);
  set_component(g, 0, 0.5, Eigen::Vector4d(2.5 * s, 0, 1.0, 0.2), diag(s * s, s * s, sz * sz, 0.01));
  set_component(g, 1, 0.5, Eigen::Vector4d(0, 0, 2.0, 0.9), diag(0.5, 0.5, sz * sz, 0.01));
  sogmm::RenderOptions o;
  o.surface_sigma = 2.0;
  sogmm::RenderedImages r = sogmm::render_expected_surface(g, cam, o);
  EXPECT_NEAR(r.depth[0], 2.0, 1e-4);
  EXPECT_NEAR(sogmm::render_expected_surface(g, cam).depth[0], 1.0, 1e-4);  // surface_sigma 0: the patch
  EXPECT_NEAR(r.gray[0], 0.9, 1e-3);
  sogmm::Gmm pair;
  pair.resize(2);
  set_component(pair, 0, 0.5, Eigen::Vector4d(2.1 * s, 0, 1.0, 0.2), diag(s * s, s * s, sz * sz, 0.01));
  set_component(pair, 1, 0.5, Eigen::Vector4d(-2.1 * s, 0, 1.0, 0.2), diag(s * s, s * s, sz * sz, 0.01));
  r = sogmm::render_expected_surface(pair, cam, o);
  EXPECT_NEAR(r.depth[0], 1.0, 1e-5);
  sogmm::Gmm one;
  one.resize(1);
  set_component(one, 0, 1.0, Eigen::Vector4d(2.1 * s, 0, 1.0, 0.2), diag(s * s, s * s, sz * sz, 0.01));
  r = sogmm::render_expected_surface(one, cam, o);
  EXPECT_TRUE(std::isnan(r.depth[0]));
}

TEST(Render, FittedPlaneIsRenderedAtThePlane) {
  // A regular grid of points on the plane z = 1.5 + 0.2 x (no randomness),
  // gray a ramp in y; fitted, then rendered from the origin.
  sogmm::PointCloud cloud;
  for (int i = 0; i <= 80; ++i)
    for (int j = 0; j <= 60; ++j) {
      const float x = -0.4f + 0.01f * i, y = -0.3f + 0.01f * j;
      cloud.xyzg.insert(cloud.xyzg.end(), {x, y, 1.5f + 0.2f * x, 0.5f + y});
    }
  sogmm::FitOptions fo;
  fo.bandwidth = 0.05;
  fo.seed = 1;
  const sogmm::FitResult f = sogmm::fit(cloud.view(), fo);
  const sogmm::Camera cam{40, 30, 40.0, 40.0, 19.5, 14.5};
  const sogmm::RenderedImages r = sogmm::render_expected_surface(f.gmm, cam);
  // Pixels whose ray meets the plane well inside the sampled patch
  // (|x| < 0.3, |y| < 0.2): the plane's depth along the ray, to 5 mm.
  std::size_t checked = 0;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const double dx = (u - cam.cx) / cam.fx, dy = (v - cam.cy) / cam.fy;
      const double t = 1.5 / (1.0 - 0.2 * dx);  // z = 1.5 + 0.2 t dx
      if (std::abs(t * dx) > 0.3 || std::abs(t * dy) > 0.2) continue;
      SCOPED_TRACE(testing::Message() << "pixel " << u << ", " << v);
      ASSERT_FALSE(std::isnan(r.depth[at(cam, u, v)]));
      EXPECT_NEAR(r.depth[at(cam, u, v)], t, 0.005);
      EXPECT_NEAR(r.gray[at(cam, u, v)], 0.5 + t * dy, 0.03);
      ++checked;
    }
  EXPECT_GT(checked, 100u);  // 164 pixels
}

TEST(Render, MovingModelAndPoseTogetherRendersTheSameImages) {
  const sogmm::Gmm g = two_surfaces();
  // A camera-to-world pose, and a rigid motion T applied to both the model
  // and the pose: the camera sees the same scene.
  const Eigen::Matrix3d Rc = Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d Rt = Eigen::AngleAxisd(-1.1, Eigen::Vector3d(-2, 1, 0.5).normalized()).toRotationMatrix();
  using sogmm_test::pose_of;
  const std::array<double, 16> camera = pose_of(Rc, Eigen::Vector3d(0.05, -0.02, -0.1));
  const std::array<double, 16> motion = pose_of(Rt, Eigen::Vector3d(1.5, -0.7, 0.3));
  const sogmm::Gmm world = sogmm::transform(g, camera);  // the scene in world coordinates
  const sogmm::RenderedImages a = sogmm::render(world, kSmall, camera);
  const sogmm::RenderedImages b =
      sogmm::render(sogmm::transform(world, motion), kSmall, sogmm::compose_poses(motion, camera));
  const sogmm::RenderedImages c = sogmm::render_expected_surface(g, kSmall);
  std::size_t shown = 0;
  for (std::size_t i = 0; i < a.depth.size(); ++i) {
    ASSERT_EQ(std::isnan(a.depth[i]), std::isnan(b.depth[i])) << "pixel " << i;
    ASSERT_EQ(std::isnan(a.depth[i]), std::isnan(c.depth[i])) << "pixel " << i;
    if (std::isnan(a.depth[i])) continue;
    ++shown;
    // float32 means moved twice (metres from the origin): 1e-5 relative.
    EXPECT_NEAR(a.depth[i], b.depth[i], 1e-5 * a.depth[i]);
    EXPECT_NEAR(a.depth[i], c.depth[i], 1e-5 * a.depth[i]);
    EXPECT_NEAR(a.gray[i], b.gray[i], 1e-4);
    EXPECT_NEAR(a.variance[i], b.variance[i], 1e-5);
  }
  EXPECT_EQ(shown, a.depth.size());  // the wall covers every pixel
}

TEST(Render, ImagesAreBitwiseTheSameForAnyThreadCount) {
  Eigen::Vector4d mu;
  Eigen::Matrix4d cov;
  const sogmm::Gmm g = sogmm::merge(two_surfaces(), tilted_component(&mu, &cov));
  const sogmm::Camera cam{48, 40, 30.0, 30.0, 23.5, 19.5};
  sogmm::RenderOptions one, three;
  one.threads = 1;
  three.threads = 3;
  const sogmm::RenderedImages a = sogmm::render_expected_surface(g, cam, one);
  const sogmm::RenderedImages b = sogmm::render_expected_surface(g, cam, three);
  ASSERT_EQ(a.depth.size(), b.depth.size());
  EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.gray.data(), b.gray.data(), a.gray.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.variance.data(), b.variance.data(), a.variance.size() * sizeof(float)));
}

TEST(Render, ReportsRowsAndCancels) {
  const sogmm::Gmm g = two_surfaces();
  const sogmm::Camera cam{9, 30, 20.0, 20.0, 4.0, 14.5};
  std::vector<sogmm::Progress> seen;
  const sogmm::RenderedImages r = sogmm::render_expected_surface(g, cam, {}, [&](const sogmm::Progress& p) {
    seen.push_back(p);
    return false;
  });
  ASSERT_GE(seen.size(), 2u);
  for (const sogmm::Progress& p : seen) {
    EXPECT_EQ(p.stage, sogmm::Stage::Rendering);
    EXPECT_EQ(p.total, 30u);
  }
  EXPECT_EQ(seen.front().step, 0u);
  EXPECT_EQ(seen.back().step, 30u);
  // The same images as without a sink.
  const sogmm::RenderedImages plain = sogmm::render_expected_surface(g, cam);
  EXPECT_EQ(0, std::memcmp(r.depth.data(), plain.depth.data(), r.depth.size() * sizeof(float)));
  sogmm_test::expect_error_codes(
      [&] { sogmm::render_expected_surface(g, cam, {}, [](const sogmm::Progress&) { return true; }); },
      {sogmm::ErrorCode::Cancelled}, {"cancel"}, "a sink that cancels");
}

TEST(Render, BadInputIsAClearError) {
  const sogmm::Gmm g = two_surfaces();
  std::array<double, 16> pose{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  pose[0] = 2.0;  // a scale, not a rotation
  sogmm_test::expect_error_codes([&] { sogmm::render(g, kSmall, pose); }, {sogmm::ErrorCode::InvalidArgument},
                                 {"pose"}, "a pose that is not rigid");
  sogmm::RenderOptions o;
  o.depth_min = 2.0;
  o.depth_max = 1.0;
  sogmm_test::expect_error_codes([&] { sogmm::render_expected_surface(g, kSmall, o); },
                                 {sogmm::ErrorCode::InvalidArgument}, {"depth_min"}, "depth_min above depth_max");
  o = {};
  o.max_mahalanobis = 0;
  sogmm_test::expect_error_codes([&] { sogmm::render_expected_surface(g, kSmall, o); },
                                 {sogmm::ErrorCode::InvalidArgument}, {"max_mahalanobis"}, "max_mahalanobis 0");
  for (double bad : {-1.0, std::nan("")}) {
    o = {};
    o.surface_sigma = bad;
    sogmm_test::expect_error_codes([&] { sogmm::render_expected_surface(g, kSmall, o); },
                                   {sogmm::ErrorCode::InvalidArgument}, {"surface_sigma"}, "surface_sigma < 0 or NaN");
  }
  sogmm_test::expect_error_codes([&] { sogmm::render_expected_surface(g, sogmm::Camera{0, 9, 1, 1, 0, 0}); },
                                 {sogmm::ErrorCode::InvalidArgument}, {"size"}, "a camera without pixels");
  sogmm_test::expect_error_codes(
      [&] { sogmm::render_expected_surface(g, sogmm::Camera{1 << 14, 1 << 14, 1, 1, 0, 0}); },
      {sogmm::ErrorCode::Limit}, {"pixels"}, "2^28 pixels");
  sogmm::Gmm flat = two_surfaces();
  for (int i = 0; i < 16; ++i) flat.covariances[16 * 3 + i] = 0.f;
  sogmm_test::expect_error_codes([&] { sogmm::render_expected_surface(flat, kSmall); },
                                 {sogmm::ErrorCode::Numeric}, {"component 3"}, "a singular component");
}

TEST(RenderScores, HandComputedCase) {
  // 2 x 2 images: pixel 0 both valid (depth off by 0.1, gray by 0.2), pixel 1
  // observed but not rendered, pixel 2 rendered but not observed, pixel 3
  // both valid (depth off by 0.3, gray exact).
  const float nan = std::nanf("");
  sogmm::RenderedImages r;
  r.width = r.height = 2;
  r.depth = {1.0f, nan, 2.0f, 1.5f};
  r.gray = {0.5f, nan, 0.1f, 0.4f};
  r.variance = {0.f, nan, 0.f, 0.f};
  const std::vector<float> depth{1.1f, 1.0f, -1.f, 1.2f}, gray{0.3f, 0.2f, 0.9f, 0.4f};
  const sogmm::RenderScores s = sogmm::score_render(r, depth, gray);
  EXPECT_EQ(s.n_observed, 3u);
  EXPECT_EQ(s.n_both, 2u);
  EXPECT_NEAR(s.empty_share, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(s.depth_mae, (0.1 + 0.3) / 2, 1e-6);
  EXPECT_NEAR(s.psnr, 10 * std::log10(1.0 / (0.04 / 2)), 1e-4);  // MSE = (0.2^2 + 0) / 2
  // Masking pixel 3 out leaves pixel 0 (and the unrendered pixel 1).
  const sogmm::RenderScores m = sogmm::score_render(r, depth, gray, {1, 1, 1, 0});
  EXPECT_EQ(m.n_observed, 2u);
  EXPECT_EQ(m.n_both, 1u);
  EXPECT_NEAR(m.depth_mae, 0.1, 1e-6);
  EXPECT_NEAR(m.psnr, 10 * std::log10(1.0 / 0.04), 1e-4);
  // Nothing in common: NaN figures, not an error.
  const sogmm::RenderScores none = sogmm::score_render(r, depth, gray, {0, 1, 1, 0});
  EXPECT_EQ(none.n_both, 0u);
  EXPECT_TRUE(std::isnan(none.depth_mae) && std::isnan(none.psnr));
  EXPECT_DOUBLE_EQ(none.empty_share, 1.0);
  sogmm_test::expect_error_codes([&] { sogmm::score_render(r, {1.f}, gray); }, {sogmm::ErrorCode::InvalidArgument},
                                 {"size"}, "images of different sizes");
}
