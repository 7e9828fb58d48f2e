// A prepared registration target (sogmm::RegistrationTarget): registering
// against it gives the bits of registering against the Gmm it was made from,
// for point and model sources, whatever other options the call changes;
// options whose levels differ from the preparation's are refused; the
// preparation copies what it needs (the Gmm may go).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <memory>
#include <vector>

#include "pose_util.hpp"
#include "registration_scenes.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/registration.hpp"
#include "test_util.hpp"

namespace {

using Pose = std::array<double, 16>;
using sogmm_test::rigid;

constexpr Pose kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

// 3000 seeded points of the corner scene, given in a frame moved by a known pose.
std::vector<float> corner_points(const sogmm::Gmm& g) {
  std::vector<float> pts(4 * 3000);
  sogmm::sample(g, 3000, 7, 4, pts.data());
  const Eigen::Matrix4d move = rigid(5.0, {0, 1, 1}, {0.02, 0.03, -0.01}).inverse();
  for (std::size_t i = 0; i < 3000; ++i) {
    const Eigen::Vector4d y = move * Eigen::Vector4d(pts[4 * i], pts[4 * i + 1], pts[4 * i + 2], 1.0);
    for (int k = 0; k < 3; ++k) pts[4 * i + k] = static_cast<float>(y(k));
  }
  return pts;
}

void expect_same_bits(const sogmm::RegistrationResult& a, const sogmm::RegistrationResult& b, const char* what) {
  EXPECT_EQ(a.pose, b.pose) << what;
  EXPECT_EQ(a.information, b.information) << what;
  EXPECT_EQ(a.log_likelihood, b.log_likelihood) << what;
  EXPECT_EQ(a.inlier_ratio, b.inlier_ratio) << what;
  EXPECT_EQ(a.rmse, b.rmse) << what;
  EXPECT_EQ(a.iterations, b.iterations) << what;
  EXPECT_EQ(a.status, b.status) << what;
}

}  // namespace

// The same bits as the Gmm calls, for both sources, and for options that do
// not shape the levels (iterations, tolerance) changed between calls on one
// preparation; the Gmm is gone before the target is used. Mutation: a
// prepared target whose finer levels are not indexed fails the model rows.
TEST(RegistrationTarget, SameBitsAsTheGmmCalls) {
  auto corner = std::make_unique<sogmm::Gmm>(sogmm_test::planes({0, 1, 2}));
  corner->support_size = 30000;
  const sogmm::Gmm kept = *corner;
  const std::vector<float> src = corner_points(kept);
  const sogmm::Gmm source = sogmm::transform(kept, sogmm_test::pose_array(rigid(4.0, {1, 0, 1}, {0.01, -0.02, 0.015})));
  sogmm::RegistrationOptions o;
  const sogmm::RegistrationTarget target(*corner, o, 2);
  corner.reset();
  for (int max_iter : {30, 3}) {
    o.max_iter = max_iter;
    o.tol = max_iter == 3 ? 1e-3 : 1e-4;
    expect_same_bits(sogmm::register_points(kept, src.data(), 3000, kIdentity, o, 2),
                     sogmm::register_points(target, src.data(), 3000, kIdentity, o, 2), "points");
    expect_same_bits(sogmm::register_model(kept, source, kIdentity, o, 1),
                     sogmm::register_model(target, source, kIdentity, o, 1), "model");
  }
}

// Each option that shapes the levels must match the preparation's.
TEST(RegistrationTarget, RefusesOptionsItWasNotPreparedFor) {
  const sogmm::Gmm corner = sogmm_test::planes({0, 1, 2});
  const std::vector<float> src = corner_points(corner);
  const sogmm::RegistrationOptions base;
  const sogmm::RegistrationTarget target(corner, base, 1);
  EXPECT_TRUE(target.prepared_for(base));
  std::vector<sogmm::RegistrationOptions> others(4, base);
  others[0].levels = 2;
  others[1].coarse_sigma = 0.05;
  others[2].outlier_ratio = 0.2;
  others[3].use_gray = false;
  for (const auto& o : others) {
    EXPECT_FALSE(target.prepared_for(o));
    sogmm_test::expect_error([&] { sogmm::register_points(target, src.data(), 3000, kIdentity, o); },
                             sogmm::ErrorCode::InvalidArgument, {"prepared target"}, "other level options");
  }
  sogmm::RegistrationOptions bad = base;
  bad.outlier_ratio = 1.0;
  sogmm_test::expect_error([&] { sogmm::RegistrationTarget(corner, bad); }, sogmm::ErrorCode::InvalidArgument,
                           {"outlier_ratio"}, "bad options at preparation");
}
