// Registration on the shared livingroom frames 0-2 (issue 32): each later
// frame's d = 5 points (and its fit, D2D) registered to the earlier frame's
// fit (bandwidth 0.02, seed 0) from the identity, against trajectory.log's relative pose
// inv(T_a) T_b; then seeded perturbations of up to 10 cm and 10 degrees
// about the truth. Skips with a message when the data folder is absent.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>

#include "pose_util.hpp"
#include "real_frame.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/model.hpp"
#include "sogmm/registration.hpp"
#include "sogmm/trajectory_log.hpp"

namespace fs = std::filesystem;

namespace {

using Pose = std::array<double, 16>;

struct Livingroom {
  std::map<int, sogmm::PointCloud> clouds;
  std::map<int, sogmm::Gmm> models;
  std::map<int, Eigen::Matrix4d> world;
};

// Loaded once for the suite: the fits take seconds.
const Livingroom* livingroom() {
  static const Livingroom* data = [] () -> const Livingroom* {
    const fs::path dir = fs::path(SOGMM_SHARED_DATA) / "rgbd" / "livingroom";
    if (!fs::is_directory(dir)) return nullptr;
    auto* d = new Livingroom;
    for (int i = 0; i < 3; ++i) {
      char name[16];
      std::snprintf(name, sizeof name, "%05d", i);
      const auto f = sogmm_test::load_frame(dir / "color" / (std::string(name) + ".jpg"),
                                            dir / "depth" / (std::string(name) + ".png"), dir / "intrinsics.json");
      d->clouds.emplace(i, sogmm_test::cloud_of(f, 1000.0, 5));
    }
    sogmm::FitOptions o;
    o.bandwidth = 0.02;
    o.seed = 0;
    for (int i : {0, 1, 2}) d->models.emplace(i, sogmm::fit(d->clouds.at(i).view(), o).gmm);
    const auto traj = sogmm::format::read_trajectory_log((dir / "trajectory.log").string());
    for (std::size_t k = 0; k < traj.poses.size(); ++k) d->world[int(traj.ids[k])] = sogmm_test::pose_matrix(traj.poses[k]);
    return d;
  }();
  return data;
}

constexpr std::array<std::pair<int, int>, 3> kPairs = {{{0, 1}, {1, 2}, {0, 2}}};

sogmm::RegistrationResult register_pair(const Livingroom& d, int a, int b, const Eigen::Matrix4d& init) {
  const sogmm::PointCloud& pc = d.clouds.at(b);
  return sogmm::register_points(d.models.at(a), pc.view().data, pc.size(), sogmm_test::pose_array(init));
}

}  // namespace

// Each pair registered from the identity by `solve` within the issue's
// bound, 1 cm and 0.5 degrees, converged.
template <typename Solve>
void expect_pairs_within_bound(const char* what, Solve solve) {
  const Livingroom* d = livingroom();
  for (const auto& [a, b] : kPairs) {
    const Eigen::Matrix4d truth = d->world.at(a).inverse() * d->world.at(b);
    const sogmm::RegistrationResult r = solve(a, b);
    const auto [dt_m, dr] = sogmm_test::pose_error(r.pose, truth);
    const double dt = 100 * dt_m;
    std::printf("livingroom %s %d->%d: %.3f cm, %.4f deg, %s, %d iterations, inliers %.3f\n", what, a, b, dt, dr,
                sogmm::status_name(r.status), r.iterations, r.inlier_ratio);
    EXPECT_EQ(r.status, sogmm::RegistrationStatus::Converged) << what << " " << a << "->" << b;
    EXPECT_LE(dt, 1.0) << what << " " << a << "->" << b;
    EXPECT_LE(dr, 0.5) << what << " " << a << "->" << b;
  }
}

// Measured with gray (the default) 0.09-0.15 cm and 0.009-0.049 degrees
// (without: 0.10-0.14 cm, 0.014-0.055 degrees), so kernel rounding (which
// moves the fit's last bits; AVX-512 rounds as the others, only wider)
// cannot cross the bound.
TEST(RegistrationReal, LivingroomPairsFromIdentity) {
  const Livingroom* d = livingroom();
  if (!d) GTEST_SKIP() << "real-frame data folder " << SOGMM_SHARED_DATA << "/rgbd/livingroom is absent";
  expect_pairs_within_bound("points", [&](int a, int b) { return register_pair(*d, a, b, Eigen::Matrix4d::Identity()); });
}

// With the frames' depth noise (depth_noise 0.001: their disparity steps'
// rounding, README, Registration): measured 0.040 / 0.051 / 0.159 cm and
// 0.015 / 0.004 / 0.049 degrees here under sse2, avx2 and AVX-512 (this
// test's frames are decoded by OpenCV; registration_eval.py's give 0.049 /
// 0.047 / 0.147 cm), and at most 0.20 cm and 0.113 degrees over the 25
// decimation offsets of the later frame (registration_eval.py --phases), so
// 0.3 cm and 0.15 degrees bound what kernel rounding can do to any draw; the
// pairs must also converge.
TEST(RegistrationReal, LivingroomPairsWithDepthNoise) {
  const Livingroom* d = livingroom();
  if (!d) GTEST_SKIP() << "real-frame data folder " << SOGMM_SHARED_DATA << "/rgbd/livingroom is absent";
  sogmm::RegistrationOptions o;
  o.depth_noise = 0.001;
  for (const auto& [a, b] : kPairs) {
    const Eigen::Matrix4d truth = d->world.at(a).inverse() * d->world.at(b);
    const sogmm::PointCloud& pc = d->clouds.at(b);
    const sogmm::RegistrationResult r = sogmm::register_points(
        d->models.at(a), pc.view().data, pc.size(), sogmm_test::pose_array(Eigen::Matrix4d::Identity()), o);
    const auto [dt_m, dr] = sogmm_test::pose_error(r.pose, truth);
    std::printf("livingroom depth noise %d->%d: %.3f cm, %.4f deg, %s\n", a, b, 100 * dt_m, dr,
                sogmm::status_name(r.status));
    EXPECT_EQ(r.status, sogmm::RegistrationStatus::Converged) << a << "->" << b;
    EXPECT_LE(100 * dt_m, 0.3) << a << "->" << b;
    EXPECT_LE(dr, 0.15) << a << "->" << b;
  }
}

// D2D: the later frame's own fit (bandwidth 0.02, seed 0, 610-639
// components) registered to the earlier frame's. Measured 0.07-0.46 cm and
// 0.021-0.164 degrees (gray, the default; the same under sse2, avx2 and
// AVX-512), so the kernels' last-bit changes to the fits cannot cross the
// bound.
TEST(RegistrationReal, LivingroomPairsModelToModel) {
  const Livingroom* d = livingroom();
  if (!d) GTEST_SKIP() << "real-frame data folder " << SOGMM_SHARED_DATA << "/rgbd/livingroom is absent";
  expect_pairs_within_bound("D2D", [&](int a, int b) {
    return sogmm::register_model(d->models.at(a), d->models.at(b), sogmm_test::pose_array(Eigen::Matrix4d::Identity()));
  });
}

// Seeded starts up to 10 cm and 10 degrees off: a converged status must come
// with a pose within 1 cm and 0.5 degrees (never a wrong pose reported as
// good), and most starts must recover.
TEST(RegistrationReal, LivingroomPerturbations) {
  const Livingroom* d = livingroom();
  if (!d) GTEST_SKIP() << "real-frame data folder " << SOGMM_SHARED_DATA << "/rgbd/livingroom is absent";
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit;
  constexpr int kTrials = 12;
  int recovered = 0;
  for (int k = 0; k < kTrials; ++k) {
    const auto [a, b] = kPairs[k % 3];
    const Eigen::Matrix4d truth = d->world.at(a).inverse() * d->world.at(b);
    const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    Eigen::Matrix4d kick = Eigen::Matrix4d::Identity();
    kick.topLeftCorner<3, 3>() = Eigen::AngleAxisd(unit(rng) * 10 * M_PI / 180, axis).toRotationMatrix();
    kick.topRightCorner<3, 1>() =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() * (unit(rng) * 0.10);
    const sogmm::RegistrationResult r = register_pair(*d, a, b, kick * truth);
    const auto [dt_m, dr] = sogmm_test::pose_error(r.pose, truth);
    const double dt = 100 * dt_m;
    const bool good = dt <= 1.0 && dr <= 0.5;
    if (r.status == sogmm::RegistrationStatus::Converged) {
      EXPECT_TRUE(good) << "trial " << k << ": converged at " << dt << " cm, " << dr << " deg";
      recovered += good;
    }
  }
  std::printf("perturbations: %d of %d recovered\n", recovered, kTrials);
  EXPECT_GE(recovered, kTrials - 1);
}
