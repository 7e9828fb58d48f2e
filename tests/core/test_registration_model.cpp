// Model-to-model (D2D) registration (sogmm::register_model) against
// independent truth: a hand-computed pair, the point registration it reduces
// to when the source's covariances vanish, a hand-made model moved by a known
// pose, thread invariance, bad input.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "pose_util.hpp"
#include "registration_scenes.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/registration.hpp"
#include "test_util.hpp"

namespace {

using sogmm::RegistrationStatus;
using Pose = std::array<double, 16>;
using sogmm_test::pose_error;
using sogmm_test::rigid;

constexpr Pose kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

// The corner of test_registration.cpp's scenes, standing for 30000 points.
sogmm::Gmm corner() {
  sogmm::Gmm g = sogmm_test::planes({0, 1, 2});
  g.support_size = 30000;
  return g;
}

// One component with mean mu and covariance cov, standing for 1000 points.
sogmm::Gmm single(const Eigen::Vector4d& mu, const Eigen::Matrix4d& cov) {
  sogmm::Gmm g;
  g.resize(1);
  sogmm_test::set_component(g, 0, 1.0, mu, cov);
  g.support_size = 1000;
  return g;
}

}  // namespace

// By hand: one source component at m against one target component at mu,
// no outlier term. The log-likelihood is that of N(m + t; mu, S + T), so
// the translation goes to mu - m in one Gauss-Newton step (the cost is
// quadratic in t), and no rotation about the source's centroid m moves the
// mean: rotations are unobservable, the status Degenerate with 3 directions,
// the rotation the identity (to rounding: the means and covariances are
// stored as float32, and the expected values are computed from those).
TEST(RegistrationModel, OnePairMovesByTheDifferenceOfTheMeans) {
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  cov.diagonal() << 0.02 * 0.02, 0.03 * 0.03, 0.01 * 0.01, 0.05 * 0.05;
  const sogmm::Gmm target = single({0.4, -0.1, 1.2, 0.5}, cov);
  const sogmm::Gmm source = single({0.35, -0.08, 1.17, 0.5}, cov);
  sogmm::RegistrationOptions o;
  o.outlier_ratio = 0.0;
  o.levels = 1;
  for (bool gray : {false, true}) {
    o.use_gray = gray;
    const sogmm::RegistrationResult r = sogmm::register_model(target, source, kIdentity, o);
    // The means as stored (float32).
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(r.pose[4 * i + 3], double(target.mean(0)[i]) - double(source.mean(0)[i]), 1e-12) << "gray " << gray;
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(r.pose[4 * i + j], i == j ? 1.0 : 0.0, 1e-12);
    }
    EXPECT_EQ(r.status, RegistrationStatus::Degenerate) << sogmm::status_name(r.status);
    EXPECT_EQ(r.unobservable, 3);
    EXPECT_DOUBLE_EQ(r.inlier_ratio, 1.0);
    // At the optimum the log-likelihood is log N(0; 0, 2 cov) (3-D or 4-D).
    const int dims = gray ? 4 : 3;
    double log_det = 0;
    for (int d = 0; d < dims; ++d) log_det += std::log(2 * double(target.covariance(0)[5 * d]));
    EXPECT_NEAR(r.log_likelihood, -0.5 * (dims * std::log(2 * M_PI) + log_det), 1e-9);
  }
}

// A model whose covariances are negligible beside the target's is a point
// cloud of its means: D2D must give the pose register_points gives for
// those means (each component one point). The source covariance 1e-12 m^2
// moves each target precision by < 1e-6 relatively; both run to tol 1e-10,
// so 1e-6 m and 1e-4 degrees bound the difference on every kernel (no
// kernel-dispatched code runs here: both are double Eigen arithmetic).
TEST(RegistrationModel, PointLikeComponentsMatchPointRegistration) {
  const sogmm::Gmm target = corner();
  const Eigen::Matrix4d truth = rigid(5.0, {1, 2, 3}, {0.03, -0.02, 0.04});
  std::vector<float> pts(4 * 3000);
  sogmm::sample(target, 3000, 7, 4, pts.data());
  const Eigen::Matrix4d back = truth.inverse();
  for (std::size_t i = 0; i < 3000; ++i) {
    const Eigen::Vector4d y = back * Eigen::Vector4d(pts[4 * i], pts[4 * i + 1], pts[4 * i + 2], 1.0);
    for (int k = 0; k < 3; ++k) pts[4 * i + k] = static_cast<float>(y(k));
  }
  sogmm::Gmm source;
  source.resize(3000);
  Eigen::Matrix4d tiny = 1e-12 * Eigen::Matrix4d::Identity();
  for (std::size_t i = 0; i < 3000; ++i)
    sogmm_test::set_component(source, i, 1.0 / 3000,
                              Eigen::Vector4d(pts[4 * i], pts[4 * i + 1], pts[4 * i + 2], pts[4 * i + 3]), tiny);
  source.support_size = 3000;
  sogmm::RegistrationOptions o;
  o.tol = 1e-10;
  o.max_iter = 60;
  o.levels = 1;  // the point path thins coarse levels; one level compares the same objective
  for (bool gray : {false, true}) {
    o.use_gray = gray;
    const auto p = sogmm::register_points(target, pts.data(), 3000, kIdentity, o);
    const auto m = sogmm::register_model(target, source, kIdentity, o);
    ASSERT_EQ(p.status, RegistrationStatus::Converged);
    ASSERT_EQ(m.status, RegistrationStatus::Converged);
    const auto [dt, dr] = pose_error(m.pose, sogmm_test::pose_matrix(p.pose));
    EXPECT_LT(dt, 1e-6) << "gray " << gray;
    EXPECT_LT(dr, 1e-4) << "gray " << gray;
    EXPECT_NEAR(m.log_likelihood, p.log_likelihood, 1e-4);
    EXPECT_NEAR(m.inlier_ratio, p.inlier_ratio, 1e-9);
  }
}

// The corner model moved by a known pose T (transform(), exact up to float
// rounding) registers back to T from the identity. The optimum of the
// overlap objective of a model against its own moved copy is T up to the
// pull of the grid's edges and the float rounding of the moved copy
// (measured 0.9 um and 2e-5 degrees); 10 um and 1e-3 degrees bound it on
// every kernel (no kernel-dispatched code runs here).
TEST(RegistrationModel, RecoversAKnownPose) {
  const sogmm::Gmm target = corner();
  const Eigen::Matrix4d truth = rigid(6.0, {1, 2, 3}, {0.03, -0.02, 0.04});
  const sogmm::Gmm source = sogmm::transform(target, sogmm_test::pose_array(truth.inverse()));
  for (bool gray : {false, true}) {
    sogmm::RegistrationOptions o;
    o.use_gray = gray;
    const sogmm::RegistrationResult r = sogmm::register_model(target, source, kIdentity, o);
    EXPECT_EQ(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
    const auto [dt, dr] = pose_error(r.pose, truth);
    EXPECT_LT(dt, 1e-5) << "gray " << gray;
    EXPECT_LT(dr, 1e-3) << "gray " << gray;
    EXPECT_GT(r.inlier_ratio, 0.95);
    EXPECT_EQ(r.unobservable, 0);
  }
}

// Partial sums run over fixed blocks: the answer is bitwise the same for
// any thread count.
TEST(RegistrationModel, ThreadCountDoesNotChangeTheAnswer) {
  const sogmm::Gmm target = corner();
  const sogmm::Gmm source = sogmm::transform(target, sogmm_test::pose_array(rigid(4.0, {0, 1, 1}, {0.02, 0, 0})));
  const auto a = sogmm::register_model(target, source, kIdentity, {}, 1);
  const auto b = sogmm::register_model(target, source, kIdentity, {}, 3);
  EXPECT_EQ(a.pose, b.pose);
  EXPECT_EQ(a.information, b.information);
  EXPECT_EQ(a.log_likelihood, b.log_likelihood);
  EXPECT_EQ(a.iterations, b.iterations);
}

// Without an outlier term (outlier_ratio 0) an item no target box holds has
// no density at all: it is left out of the sums (not an inlier) instead of
// making the pose and the figures NaN, for a model and for points alike.
TEST(RegistrationModel, AnItemNoComponentReachesIsLeftOutWithoutAnOutlierTerm) {
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  cov.diagonal() << 0.02 * 0.02, 0.03 * 0.03, 0.01 * 0.01, 0.05 * 0.05;
  const sogmm::Gmm target = single({0.4, -0.1, 1.2, 0.5}, cov);
  sogmm::Gmm source;
  source.resize(2);
  sogmm_test::set_component(source, 0, 0.5, {0.35, -0.08, 1.17, 0.5}, cov);
  sogmm_test::set_component(source, 1, 0.5, {5.0, 5.0, 5.0, 0.5}, cov);  // metres from every box
  source.support_size = 1000;
  sogmm::RegistrationOptions o;
  o.outlier_ratio = 0.0;
  o.levels = 1;
  o.use_gray = false;
  const sogmm::RegistrationResult r = sogmm::register_model(target, source, kIdentity, o);
  // The near component's mean lands on the target's (the far one pulls
  // nothing; which rigid motion does it is not unique with one pair).
  for (int i = 0; i < 3; ++i) {
    double moved = r.pose[4 * i + 3];
    for (int j = 0; j < 3; ++j) moved += r.pose[4 * i + j] * double(source.mean(0)[j]);
    EXPECT_NEAR(moved, double(target.mean(0)[i]), 1e-9);
  }
  EXPECT_TRUE(std::isfinite(r.log_likelihood));
  EXPECT_DOUBLE_EQ(r.inlier_ratio, 0.5);
  for (double v : r.information) EXPECT_TRUE(std::isfinite(v));
  // The same with points: 200 at the source's near mean, one far away.
  std::vector<float> pts;
  for (int k = 0; k < 200; ++k) pts.insert(pts.end(), source.mean(0), source.mean(0) + 4);
  pts.insert(pts.end(), source.mean(1), source.mean(1) + 4);
  const sogmm::RegistrationResult p = sogmm::register_points(target, pts.data(), 201, kIdentity, o);
  EXPECT_TRUE(std::isfinite(p.log_likelihood));
  EXPECT_NEAR(p.inlier_ratio, 200.0 / 201.0, 1e-12);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(std::isfinite(p.pose[4 * i + 3]));
}

TEST(RegistrationModel, BadInput) {
  const sogmm::Gmm target = corner();
  using sogmm::ErrorCode;
  sogmm_test::expect_error([&] { sogmm::register_model(target, sogmm::Gmm{}, kIdentity); }, ErrorCode::InvalidData,
                           {"no component"}, "empty source");
  sogmm::Gmm few = target;
  few.support_size = 50;
  sogmm_test::expect_error([&] { sogmm::register_model(target, few, kIdentity); }, ErrorCode::InvalidData,
                           {"min_points"}, "a source standing for 50 points");
  Pose nan = kIdentity;
  nan[3] = std::numeric_limits<double>::quiet_NaN();
  sogmm_test::expect_error([&] { sogmm::register_model(target, target, nan); }, ErrorCode::InvalidArgument,
                           {"initial pose"}, "NaN initial pose");
  sogmm::Gmm bad = target;
  bad.covariances[16 * 5] = -1.0f;  // component 5 no longer positive definite
  EXPECT_THROW(sogmm::register_model(target, bad, kIdentity), sogmm::Error);
  sogmm::RegistrationOptions o;
  o.levels = 0;
  sogmm_test::expect_error([&] { sogmm::register_model(target, target, kIdentity, o); }, ErrorCode::InvalidArgument,
                           {"levels"}, "zero levels");
}
