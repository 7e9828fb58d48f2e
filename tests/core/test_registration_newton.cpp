// The point registration's steps (sogmm/registration.hpp): Newton steps on
// the observed information where it constrains every direction, and the
// answer is the pose whose step fell below tol, reported with the figures of
// that very pose.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <vector>

#include "pose_util.hpp"
#include "registration_scenes.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/registration.hpp"

namespace {

using sogmm::RegistrationStatus;
using Pose = std::array<double, 16>;
using sogmm_test::planes;
using sogmm_test::rigid;
using sogmm_test::samples;

constexpr Pose kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

}  // namespace

// The corner's three planes constrain every direction, so each level takes
// Newton steps, and the error falls quadratically: from a start 1-3 cm and 4
// degrees off, within 3 evaluations a level (7 in all on every kernel;
// Gauss-Newton steps alone took 12-13, each level converging linearly).
TEST(RegistrationNewton, ConvergesWithinThreeEvaluationsALevel) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  for (double cm : {1.0, 3.0}) {
    const Eigen::Matrix4d truth = rigid(4.0, {1, 2, 3}, {0.01 * cm, -0.005 * cm, 0.008 * cm});
    const std::vector<float> src = samples(corner, 6000, truth.inverse());
    const sogmm::RegistrationOptions o;
    const auto r = sogmm::register_points(corner, src.data(), 6000, kIdentity, o);
    EXPECT_EQ(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
    EXPECT_LE(r.iterations, 3 * o.levels) << cm << " cm";
    const auto [dt, dr] = sogmm_test::pose_error(r.pose, truth);
    EXPECT_LT(dt, 1e-3);
    EXPECT_LT(dr, 0.1);
  }
}

// The answer is the pose whose step fell below tol, and its figures are that
// pose's: one unsmoothed level started there evaluates the same pose once
// (its step is the same, below tol) and reports the same pose, log-likelihood,
// inlier ratio and information, to rounding (the rotation is
// re-orthonormalised on return: 1e-16). Taking that last step after the
// figures moves the pose by 1e-11 to 3e-10 here, which fails the pose check.
TEST(RegistrationNewton, FiguresAreThoseOfTheReturnedPose) {
  const sogmm::Gmm corner = planes({0, 1, 2});
  const Eigen::Matrix4d truth = rigid(5.0, {0, 1, 1}, {0.02, 0.03, -0.01});
  const std::vector<float> src = samples(corner, 6000, truth.inverse());
  const auto r = sogmm::register_points(corner, src.data(), 6000, kIdentity);
  ASSERT_EQ(r.status, RegistrationStatus::Converged) << sogmm::status_name(r.status);
  sogmm::RegistrationOptions once;
  once.levels = 1;
  once.max_iter = 1;
  const auto again = sogmm::register_points(corner, src.data(), 6000, r.pose, once);
  ASSERT_EQ(again.status, RegistrationStatus::Converged) << sogmm::status_name(again.status);
  EXPECT_EQ(again.iterations, 1);
  for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(again.pose[i], r.pose[i], 1e-12) << i;
  EXPECT_NEAR(again.log_likelihood, r.log_likelihood, 1e-12 * std::abs(r.log_likelihood));
  EXPECT_NEAR(again.inlier_ratio, r.inlier_ratio, 1e-12);
  double top = 0.0;
  for (double v : r.information) top = std::max(top, std::abs(v));
  for (std::size_t i = 0; i < 36; ++i) EXPECT_NEAR(again.information[i], r.information[i], 1e-9 * top) << i;
}
