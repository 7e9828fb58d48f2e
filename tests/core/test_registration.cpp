// Point-to-model registration (sogmm/registration.hpp) against closed-form
// truth: points sampled from a hand-made model and moved by a known pose are
// registered back to that pose; invariances; a single plane is degenerate
// in exactly its three in-plane directions; bad input.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "sogmm/component_index.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/registration.hpp"
#include "pose_util.hpp"
#include "registration_scenes.hpp"
#include "test_util.hpp"

namespace {

using sogmm::RegistrationStatus;
using Pose = std::array<double, 16>;
using sogmm_test::planes;
using sogmm_test::pose_error;
using sogmm_test::rigid;
using sogmm_test::samples;

constexpr Pose kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

}  // namespace

// Points x of the corner model, given as p = T^-1 x: the registration must
// return T. Estimation noise is about 3 mm / sqrt(2000) = 0.07 mm per
// plane normal, so 1 mm and 0.1 degree bound it by more than 10x on every
// kernel (the kernels only change the sampling's last float bits).
TEST(Registration, RecoversAKnownPose) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  for (bool gray : {false, true}) {
    const Eigen::Matrix4d truth = rigid(6.0, {1, 2, 3}, {0.03, -0.02, 0.04});
    const std::vector<float> src = samples(corner, 6000, truth.inverse());
    sogmm::RegistrationOptions o;
    o.use_gray = gray;
    const sogmm::RegistrationResult r = sogmm::register_points(corner, src.data(), 6000, kIdentity, o);
    EXPECT_EQ(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
    const auto [dt, dr] = pose_error(r.pose, truth);
    EXPECT_LT(dt, 1e-3) << "gray " << gray;
    EXPECT_LT(dr, 0.1) << "gray " << gray;
    EXPECT_GT(r.inlier_ratio, 0.95);
    EXPECT_EQ(r.unobservable, 0);
    EXPECT_GT(r.iterations, 1);
    // Points spread as the model says: the Mahalanobis RMS is about 1.
    EXPECT_NEAR(r.rmse, 1.0, 0.2);
    EXPECT_TRUE(std::isfinite(r.log_likelihood));
  }
}

TEST(Registration, IdentityStaysIdentity) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  const std::vector<float> src = samples(corner, 6000, Eigen::Matrix4d::Identity());
  const sogmm::RegistrationResult r = sogmm::register_points(corner, src.data(), 6000, kIdentity);
  EXPECT_EQ(r.status, RegistrationStatus::Converged);
  const auto [dt, dr] = pose_error(r.pose, Eigen::Matrix4d::Identity());
  EXPECT_LT(dt, 1e-3);
  EXPECT_LT(dr, 0.1);
}

// Moving source and target by the same translation D changes the answer
// from [R t] to [R, t + D - R D] exactly (up to the float rounding of the
// shifted points, 1e-7 m at 3 m, and the stopping tolerance).
TEST(Registration, GlobalTranslationInvariance) {
  const Eigen::Vector3d shift(3.0, -2.0, 1.5);
  const Eigen::Matrix4d truth = rigid(4.0, {0, 1, 1}, {0.02, 0.01, -0.03});
  const std::vector<float> src = samples(planes({0, 1, 2}), 5000, truth.inverse());
  std::vector<float> moved = src;
  for (std::size_t i = 0; i < 5000; ++i)
    for (int k = 0; k < 3; ++k) moved[4 * i + k] = static_cast<float>(src[4 * i + k] + shift(k));
  sogmm::RegistrationOptions o;
  o.tol = 1e-8;
  const auto a = sogmm::register_points(planes({0, 1, 2}), src.data(), 5000, kIdentity, o);
  const auto b = sogmm::register_points(planes({0, 1, 2}, shift), moved.data(), 5000, kIdentity, o);
  ASSERT_EQ(a.status, RegistrationStatus::Converged);
  ASSERT_EQ(b.status, RegistrationStatus::Converged);
  Eigen::Matrix4d expect = sogmm_test::pose_matrix(a.pose);
  expect.topRightCorner<3, 1>() += shift - expect.topLeftCorner<3, 3>() * shift;
  const auto [dt, dr] = pose_error(b.pose, expect);
  EXPECT_LT(dt, 2e-5);
  EXPECT_LT(dr, 1e-3);
}

// One plane (z = 0) constrains z, tilt about x and tilt about y; sliding
// along x, y and turning about z leave its likelihood flat (up to the edges).
TEST(Registration, SinglePlaneIsDegenerate) {
  const sogmm::Gmm plane = planes({2});
  const std::vector<float> src = samples(plane, 4000, rigid(2.0, {1, 0, 0}, {0, 0, 0.01}).inverse());
  sogmm::RegistrationOptions o;
  o.use_gray = false;  // the geometry alone (the components' gray varies across the plane and would pin it)
  const sogmm::RegistrationResult r = sogmm::register_points(plane, src.data(), 4000, kIdentity, o);
  EXPECT_EQ(r.status, RegistrationStatus::Degenerate) << sogmm::status_name(r.status);
  EXPECT_EQ(r.unobservable, 3);
  EXPECT_LT(r.eigen_ratio, 1e-3);
  Eigen::Matrix<double, 6, 6> info;
  for (int i = 0; i < 36; ++i) info(i / 6, i % 6) = r.information[i];
  const double z = info(5, 5);  // tz
  EXPECT_GT(z, 0);
  // rx, ry (scaled by the ~0.4 m radius) are as stiff as z; tx, ty, rz are not.
  EXPECT_GT(info(0, 0), 0.01 * z);
  EXPECT_GT(info(1, 1), 0.01 * z);
  EXPECT_LT(std::fabs(info(3, 3)), 1e-3 * z);
  EXPECT_LT(std::fabs(info(4, 4)), 1e-3 * z);
  EXPECT_LT(std::fabs(info(2, 2)), 1e-3 * z);
  // The observable directions are still solved: tz and the tilt about x.
  const Eigen::Matrix4d p = sogmm_test::pose_matrix(r.pose);
  EXPECT_NEAR(p(2, 3), 0.01, 1e-3);
  EXPECT_NEAR(std::asin(p(2, 1)) * 180 / M_PI, 2.0, 0.1);
}

namespace {

// Two components 1 m apart, each with a grid of points about it, in a frame
// with z > 0 (as a sensor's).
struct TwoComponents {
  sogmm::Gmm g;
  std::vector<float> pts;
  std::vector<Eigen::Matrix4d> stored;
  TwoComponents();
};

TwoComponents::TwoComponents() : stored(2) {
  Eigen::Matrix4d a;
  a << 0.05, 0.01, 0.0, 0.0, -0.01, 0.03, 0.005, 0.0, 0.02, 0.0, 0.01, 0.0, 0.01, -0.02, 0.005, 0.05;
  const Eigen::Vector4d mus[2] = {{0.3, -0.2, 1.5, 0.4}, {1.3, 0.1, 1.8, 0.6}};
  const Eigen::Matrix4d flip = Eigen::Vector4d(1, -1, 1, 1).asDiagonal();
  const Eigen::Matrix4d covs[2] = {a * a.transpose(), flip * a.transpose() * a * flip};
  g.resize(2);
  for (std::size_t k = 0; k < 2; ++k) sogmm_test::set_component(g, k, 0.5, mus[k], covs[k]);
  g.support_size = 1;
  // Per component a 7 x 7 x 7 grid mu + L u (L L^T the spatial covariance,
  // u in [-1, 1]^3): Mahalanobis radius at most sqrt(3), so every point
  // stays inside its own 3-sigma box near the identity, where this spread
  // holds the pose. Gray varies along the grid.
  for (std::size_t k = 0; k < 2; ++k) {
    stored[k] = sogmm_test::cov_of(g, k);
    stored[k] = 0.5 * (stored[k] + stored[k].transpose()).eval();
    const Eigen::Matrix3d chol = Eigen::LLT<Eigen::Matrix3d>(stored[k].topLeftCorner<3, 3>()).matrixL();
    for (int i = -3; i <= 3; ++i)
      for (int j = -3; j <= 3; ++j)
        for (int l = -3; l <= 3; ++l) {
          const Eigen::Vector3d x = mus[k].head<3>() + chol * Eigen::Vector3d(i, j, l) / 3.0;
          for (int d = 0; d < 3; ++d) pts.push_back(float(x(d)));
          pts.push_back(float(mus[k](3) + 0.01 * (i - j + l)));
        }
  }
}

}  // namespace

// Two components 1 m apart (3-sigma boxes about 0.15 m wide) and no outlier
// term: every point has one candidate and responsibility exactly 1, so
// Louis' correction vanishes and the information about the origin is the
// Gauss-Newton sum over the points x (at the returned pose) of J^T P_k J,
// with J = [-[x]x, I] and P_k its component's spatial precision (with gray:
// the conditional one, the inverse of the Schur complement of s_gg).
// Computed here from the stored float covariances, independently of the
// library's blockwise sum about the centroid; a sign or transpose slip in one
// block of that sum (tried: the sign of the rotation-translation block,
// which a single component's symmetric points cancel) breaks the 1e-9
// relative bound, which leaves room for rounding only (no kernel-dispatched
// code runs here, so every kernel gives the same sums).
TEST(Registration, InformationIsTheGaussNewtonSum) {
  const TwoComponents scene;
  const sogmm::Gmm& g = scene.g;
  const std::vector<float>& pts = scene.pts;
  const std::vector<Eigen::Matrix4d>& stored = scene.stored;
  const std::size_t n = pts.size() / 4, per = n / 2;
  for (bool gray : {false, true}) {
    sogmm::RegistrationOptions o;
    o.use_gray = gray;
    o.outlier_ratio = 0.0;
    o.levels = 1;
    const sogmm::RegistrationResult r =
        sogmm::register_points(g, pts.data(), n, sogmm_test::pose_array(rigid(1.0, {0, 0, 1}, {0.002, 0, 0})), o);
    ASSERT_EQ(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
    const Eigen::Matrix4d pose = sogmm_test::pose_matrix(r.pose);
    Eigen::Matrix<double, 6, 6> expected = Eigen::Matrix<double, 6, 6>::Zero();
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t k = p / per;
      Eigen::Matrix3d spatial = stored[k].topLeftCorner<3, 3>();
      if (gray) spatial -= stored[k].block<3, 1>(0, 3) * stored[k].block<1, 3>(3, 0) / stored[k](3, 3);
      const Eigen::Vector3d x =
          pose.topLeftCorner<3, 3>() * Eigen::Vector3d(pts[4 * p], pts[4 * p + 1], pts[4 * p + 2]) +
          pose.topRightCorner<3, 1>();
      const double xyz[3] = {x(0), x(1), x(2)};
      ASSERT_TRUE(sogmm::component_box(g, k, 3.0).contains(xyz));
      ASSERT_FALSE(sogmm::component_box(g, 1 - k, 3.0).contains(xyz));
      Eigen::Matrix<double, 3, 6> jac;
      jac << 0, x(2), -x(1), 1, 0, 0, -x(2), 0, x(0), 0, 1, 0, x(1), -x(0), 0, 0, 0, 1;
      expected += jac.transpose() * spatial.inverse() * jac;
    }
    Eigen::Matrix<double, 6, 6> info;
    for (int i = 0; i < 36; ++i) info(i / 6, i % 6) = r.information[i];
    EXPECT_LT((info - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff()) << "gray " << gray;
  }
}

// With depth noise k, each point p (here the grids of TwoComponents, given
// in a sensor frame turned by 20 degrees and 0.6 m away from the target's, so
// that R p differs from the target-frame point and p's depth z from its
// target-frame z; u taken from the target-frame point fails it) is scored
// under its component's (conditional) spatial
// covariance plus u u^T, u = k z R p (R the returned rotation): computed
// here by forming that 3 x 3 covariance and inverting it, independently of
// the kernel's rank-one update. With one candidate per point and no outlier
// term, the mean log-likelihood is the mean of log 0.5 + (with gray) the
// gray marginal + log N(r; 0, S + u u^T), and the information the sum of
// J^T (S + u u^T)^-1 J (the source covariance held, as in the step). k =
// 0.01 makes u 1.4 to 4.4 cm, larger than the components' 1-5 cm sigmas, so
// a formula that dropped u, its log det, or rotated it wrongly is off by far
// more than the 1e-9 relative bounds (rounding and fast_log_ge1's 1e-15).
TEST(Registration, DepthNoiseAddsEachPointsRayCovariance) {
  const TwoComponents scene;
  const std::size_t n = scene.pts.size() / 4, per = n / 2;
  const Eigen::Matrix4d sensor = rigid(20.0, {1, 2, 3}, {0.3, -0.2, -0.5});  // sensor to target frame
  std::vector<float> pts = scene.pts;
  for (std::size_t p = 0; p < n; ++p) {
    const Eigen::Vector4d y = sensor.inverse() * Eigen::Vector4d(pts[4 * p], pts[4 * p + 1], pts[4 * p + 2], 1.0);
    ASSERT_GT(y(2), 0.5);  // in front of the sensor
    for (int d = 0; d < 3; ++d) pts[4 * p + d] = static_cast<float>(y(d));
  }
  for (bool gray : {false, true}) {
    sogmm::RegistrationOptions o;
    o.use_gray = gray;
    o.outlier_ratio = 0.0;
    o.levels = 1;
    o.depth_noise = 0.01;
    const sogmm::RegistrationResult r = sogmm::register_points(
        scene.g, pts.data(), n, sogmm_test::pose_array(sensor * rigid(1.0, {0, 0, 1}, {0.002, 0, 0})), o);
    ASSERT_EQ(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
    const Eigen::Matrix4d pose = sogmm_test::pose_matrix(r.pose);
    const Eigen::Matrix3d rot = pose.topLeftCorner<3, 3>();
    Eigen::Matrix<double, 6, 6> expected = Eigen::Matrix<double, 6, 6>::Zero();
    double log_likelihood = 0.0;
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t k = p / per;
      const Eigen::Matrix4d& c = scene.stored[k];
      const Eigen::Vector3d src(pts[4 * p], pts[4 * p + 1], pts[4 * p + 2]);
      const Eigen::Vector3d x = rot * src + pose.topRightCorner<3, 1>();
      const double dg = double(pts[4 * p + 3]) - double(scene.g.mean(k)[3]);
      Eigen::Matrix3d spatial = c.topLeftCorner<3, 3>();
      Eigen::Vector3d res = x - Eigen::Vector3d(scene.g.mean(k)[0], scene.g.mean(k)[1], scene.g.mean(k)[2]);
      double lp = std::log(0.5);
      if (gray) {
        spatial -= c.block<3, 1>(0, 3) * c.block<1, 3>(3, 0) / c(3, 3);
        res -= c.block<3, 1>(0, 3) / c(3, 3) * dg;
        lp += -0.5 * std::log(2 * M_PI * c(3, 3)) - 0.5 * dg * dg / c(3, 3);
      }
      const Eigen::Vector3d u = 0.01 * src(2) * (rot * src);
      const Eigen::Matrix3d cov = spatial + u * u.transpose();
      const Eigen::Matrix3d prec = cov.inverse();
      lp += -0.5 * std::log((2 * M_PI) * (2 * M_PI) * (2 * M_PI) * cov.determinant()) - 0.5 * res.dot(prec * res);
      log_likelihood += lp;
      Eigen::Matrix<double, 3, 6> jac;
      jac << 0, x(2), -x(1), 1, 0, 0, -x(2), 0, x(0), 0, 1, 0, x(1), -x(0), 0, 0, 0, 1;
      expected += jac.transpose() * prec * jac;
    }
    log_likelihood /= double(n);
    EXPECT_NEAR(r.log_likelihood, log_likelihood, 1e-9 * std::abs(log_likelihood)) << "gray " << gray;
    Eigen::Matrix<double, 6, 6> info;
    for (int i = 0; i < 36; ++i) info(i / 6, i % 6) = r.information[i];
    EXPECT_LT((info - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff()) << "gray " << gray;
  }
}

// A start beyond the target's reach does not come back as a good pose.
TEST(Registration, FarStartReportsFailure) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  const std::vector<float> src = samples(corner, 3000, rigid(0, {0, 0, 1}, {2.0, 2.0, 2.0}));
  const sogmm::RegistrationResult r = sogmm::register_points(corner, src.data(), 3000, kIdentity);
  EXPECT_NE(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
  EXPECT_LT(r.inlier_ratio, 0.5);
}

TEST(Registration, IterationCapIsNotConverged) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  const std::vector<float> src = samples(corner, 3000, rigid(8.0, {1, 0, 0}, {0.05, 0, 0}));
  sogmm::RegistrationOptions o;
  o.levels = 1;
  o.max_iter = 1;
  const sogmm::RegistrationResult r = sogmm::register_points(corner, src.data(), 3000, kIdentity, o);
  EXPECT_EQ(r.status, RegistrationStatus::NotConverged);
  EXPECT_EQ(r.iterations, 1);
}

// Partial sums run over fixed blocks of points (the coarsest level's 750
// points here, every 4th, in 6 blocks): the answer is bitwise the same for
// any thread count (the same kernel runs whatever the team).
TEST(Registration, ThreadCountDoesNotChangeTheAnswer) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  const std::vector<float> src = samples(corner, 3000, rigid(5.0, {0, 1, 1}, {0.02, 0.03, -0.01}).inverse());
  const auto one = sogmm::register_points(corner, src.data(), 3000, kIdentity, {}, 1);
  for (int threads : {2, 3}) {
    const auto r = sogmm::register_points(corner, src.data(), 3000, kIdentity, {}, threads);
    EXPECT_EQ(one.pose, r.pose) << threads;
    EXPECT_EQ(one.information, r.information) << threads;
    EXPECT_EQ(one.log_likelihood, r.log_likelihood) << threads;
    EXPECT_EQ(one.inlier_ratio, r.inlier_ratio) << threads;
    EXPECT_EQ(one.iterations, r.iterations) << threads;
  }
}

TEST(Registration, BadInput) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  std::vector<float> src = samples(corner, 500, Eigen::Matrix4d::Identity());
  using sogmm::ErrorCode;
  sogmm_test::expect_error([&] { sogmm::register_points(corner, src.data(), 50, kIdentity); },
                           ErrorCode::InvalidData, {"min_points"}, "too few points");
  Pose nan = kIdentity;
  nan[3] = std::numeric_limits<double>::quiet_NaN();
  sogmm_test::expect_error([&] { sogmm::register_points(corner, src.data(), 500, nan); }, ErrorCode::InvalidArgument,
                           {"initial pose"}, "NaN initial pose");
  Pose scaled = kIdentity;
  scaled[0] = 2.0;
  sogmm_test::expect_error([&] { sogmm::register_points(corner, src.data(), 500, scaled); },
                           ErrorCode::InvalidArgument, {"initial pose"}, "non-rigid initial pose");
  src[4 * 17 + 1] = std::numeric_limits<float>::infinity();
  sogmm_test::expect_error([&] { sogmm::register_points(corner, src.data(), 500, kIdentity); },
                           ErrorCode::InvalidData, {"row 17"}, "infinite point");
  sogmm::RegistrationOptions o;
  o.outlier_ratio = 1.0;
  sogmm_test::expect_error([&] { sogmm::register_points(corner, src.data(), 500, kIdentity, o); },
                           ErrorCode::InvalidArgument, {"outlier_ratio"}, "outlier ratio 1");
  o = {};
  for (double bad : {-1e-3, std::numeric_limits<double>::quiet_NaN(), 1.5}) {
    o.depth_noise = bad;
    sogmm_test::expect_error([&] { sogmm::register_points(corner, src.data(), 500, kIdentity, o); },
                             ErrorCode::InvalidArgument, {"depth_noise"}, "depth noise out of range");
  }
}
