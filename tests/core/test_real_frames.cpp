// Real frames (livingroom 00000, TUM): fit at d = 5, bandwidth 0.02; validity
// and M within 2% of the authors' 628. Skips with a message when the data
// folder is absent.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/reg_covar.hpp"
#include "real_frame.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;

using sogmm_test::cloud_of;
using sogmm_test::Frame;
using sogmm_test::load_frame;

TEST(RealFrames, LivingroomFrame0Bandwidth002) {
  const fs::path dir = fs::path(SOGMM_SHARED_DATA) / "rgbd" / "livingroom";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "real-frame data folder " << dir << " is absent";
  const Frame f = load_frame(dir / "color" / "00000.jpg", dir / "depth" / "00000.png", dir / "intrinsics.json");
  EXPECT_EQ(f.camera.width, 640);
  EXPECT_EQ(f.camera.height, 480);
  const sogmm::PointCloud pc = cloud_of(f, 1000.0, 5);
  // About 12k valid points at 128x96 (reference.md: N = 10674).
  EXPECT_GT(pc.size(), 9000u);
  EXPECT_LE(pc.size(), 128u * 96u);
  sogmm::FitOptions o;
  o.bandwidth = 0.02;
  const auto t0 = std::chrono::steady_clock::now();
  const sogmm::FitResult r = sogmm::fit(pc.view(), o);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  RecordProperty("components", static_cast<int>(r.gmm.size()));
  RecordProperty("points", static_cast<int>(pc.size()));
  std::printf("livingroom 00000: N = %zu, M = %zu, EM iterations %d, LL %.4f, %.2f s\n", pc.size(), r.gmm.size(),
              r.em.iterations, r.em.log_likelihood, secs);
  EXPECT_TRUE(sogmm_test::model_is_valid(r.gmm));
  EXPECT_EQ(r.n_points, pc.size());
  EXPECT_TRUE(std::isfinite(r.em.log_likelihood));
  // Authors' code: M = 628 at 0.02; acceptance within 2%.
  EXPECT_GE(r.gmm.size(), 616u);
  EXPECT_LE(r.gmm.size(), 640u);
  // The model explains its own points better than a single Gaussian would.
  sogmm::FitOptions one;
  one.n_components = 1;
  const sogmm::FitResult r1 = sogmm::fit(pc.view(), one);
  EXPECT_GT(r.em.log_likelihood, r1.em.log_likelihood + 1.0);
  // Regressed gray is finite and in a sane range at every point.
  std::vector<float> xyz, g(pc.size());
  for (std::size_t i = 0; i < pc.size(); ++i)
    xyz.insert(xyz.end(), {pc.xyzg[4 * i], pc.xyzg[4 * i + 1], pc.xyzg[4 * i + 2]});
  sogmm::regress_gray(r.gmm, xyz.data(), pc.size(), g.data(), nullptr);
  for (std::size_t i = 0; i < pc.size(); ++i) ASSERT_TRUE(std::isfinite(g[i]) && g[i] > -0.5f && g[i] < 1.5f) << i;
}

TEST(RealFrames, TumFrameFitIsValid) {
  const fs::path dir = fs::path(SOGMM_SHARED_DATA) / "rgbd" / "tum";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "real-frame data folder " << dir << " is absent";
  const Frame f = load_frame(dir / "color.png", dir / "depth.png", dir / "intrinsics.json");
  const sogmm::PointCloud pc = cloud_of(f, 5000.0, 5);
  ASSERT_GT(pc.size(), 1000u);
  sogmm::FitOptions o;
  o.bandwidth = 0.03;
  const sogmm::FitResult r = sogmm::fit(pc.view(), o);
  std::printf("tum: N = %zu, M = %zu, EM iterations %d\n", pc.size(), r.gmm.size(), r.em.iterations);
  EXPECT_GT(r.gmm.size(), 10u);
  EXPECT_TRUE(sogmm_test::model_is_valid(r.gmm));
}

// The automatic reg_covar (issue 14) on the shared frames: they measure
// 0.79-0.95 m from their median and have gray in [0, 1], so both floors are
// exactly the paper's 1e-6 and the default fit is the fit with an explicit
// 1e-6, bit for bit (checked here at d = 5 on livingroom 00000).
TEST(RealFrames, AutomaticRegCovarIsThePapersValue) {
  const fs::path root = fs::path(SOGMM_SHARED_DATA) / "rgbd";
  if (!fs::is_directory(root / "livingroom")) GTEST_SKIP() << "real-frame data folder " << root << " is absent";
  const fs::path lr = root / "livingroom";
  for (const char* i : {"00000", "00001", "00002"})
    for (int d : {2, 5}) {
      SCOPED_TRACE(std::string("livingroom ") + i + ", d = " + std::to_string(d));
      const Frame f = load_frame(lr / "color" / (std::string(i) + ".jpg"), lr / "depth" / (std::string(i) + ".png"),
                                 lr / "intrinsics.json");
      const sogmm::RegCovarFloors r = sogmm::auto_reg_covar(cloud_of(f, 1000.0, d).view());
      EXPECT_EQ(r.spatial, 1e-6);
      EXPECT_EQ(r.gray, 1e-6);
    }
  if (fs::is_directory(root / "tum")) {
    const Frame f = load_frame(root / "tum" / "color.png", root / "tum" / "depth.png", root / "tum" / "intrinsics.json");
    const sogmm::RegCovarFloors r = sogmm::auto_reg_covar(cloud_of(f, 5000.0, 5).view());
    EXPECT_EQ(r.spatial, 1e-6);
    EXPECT_EQ(r.gray, 1e-6);
  }
  const Frame f = load_frame(lr / "color" / "00000.jpg", lr / "depth" / "00000.png", lr / "intrinsics.json");
  const sogmm::PointCloud pc = cloud_of(f, 1000.0, 5);
  sogmm::FitOptions o;
  o.bandwidth = 0.02;
  const sogmm::FitResult automatic = sogmm::fit(pc.view(), o);
  o.em.reg_covar = 1e-6;
  const sogmm::FitResult explicit_value = sogmm::fit(pc.view(), o);
  EXPECT_TRUE(sogmm_test::bit_identical(automatic.gmm, explicit_value.gmm));
  EXPECT_EQ(automatic.em.log_likelihood, explicit_value.em.log_likelihood);
}
