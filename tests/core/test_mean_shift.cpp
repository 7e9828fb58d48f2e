// Flat mean shift against scikit-learn's MeanShift(bin_seeding=True,
// min_bin_freq=1, cluster_all=True); range/gray features; blurring variant.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sogmm/mean_shift.hpp"
#include "test_util.hpp"

namespace {

void run_fixture(const std::string& name, sogmm::BinAnchor anchor) {
  const nlohmann::json ref = sogmm_test::load_fixture(name);
  std::vector<double> pts;
  for (const auto& row : ref.at("points"))
    for (const auto& v : row) pts.push_back(v.get<double>());
  const double h = ref.at("bandwidth").get<double>();
  sogmm::MeanShiftOptions o;
  o.anchor = anchor;
  const sogmm::MeanShiftResult r = sogmm::mean_shift_flat(pts, h, o);
  const auto& centers = ref.at("centers");
  const auto& strengths = ref.at("strengths");
  ASSERT_EQ(r.size(), centers.size()) << "number of modes differs from scikit-learn";
  ASSERT_EQ(r.centers.size(), 2 * r.size());
  // Ordered by strength, most first.
  for (std::size_t i = 1; i < r.size(); ++i) EXPECT_GE(r.strengths[i - 1], r.strengths[i]) << i;
  // Same set of centres (sklearn order = strength order; ties may be ordered
  // differently, so match each sklearn centre to one of ours).
  std::vector<bool> used(r.size(), false);
  for (std::size_t i = 0; i < centers.size(); ++i) {
    const double cx = centers[i][0].get<double>(), cy = centers[i][1].get<double>();
    std::size_t best = r.size();
    double bd = 1e300;
    for (std::size_t j = 0; j < r.size(); ++j) {
      const double d = std::hypot(r.centers[2 * j] - cx, r.centers[2 * j + 1] - cy);
      if (!used[j] && d < bd) {
        bd = d;
        best = j;
      }
    }
    ASSERT_LT(best, r.size());
    EXPECT_LT(bd, 1e-9) << "sklearn centre " << i << " (" << cx << ", " << cy << ") has no match";
    used[best] = true;
    EXPECT_EQ(r.strengths[best], strengths[i].get<std::size_t>()) << "strength of sklearn centre " << i;
    // Where strengths are distinct the order must agree exactly.
    const bool tie = (i > 0 && strengths[i - 1] == strengths[i]) ||
                     (i + 1 < centers.size() && strengths[i + 1] == strengths[i]);
    if (!tie) {
      EXPECT_EQ(best, i) << "sklearn centre " << i << " is at position " << best;
    }
  }
}

}  // namespace

TEST(MeanShiftFlat, MatchesSklearnZeroAnchor) {
  run_fixture("meanshift_sklearn_zero.json", sogmm::BinAnchor::Zero);
}

TEST(MeanShiftFlat, MatchesSklearnManyModesSmallBandwidth) {
  run_fixture("meanshift_sklearn_gauss_small_h.json", sogmm::BinAnchor::Zero);
}

TEST(MeanShiftFlat, DataMinAnchorMatchesSklearnWithAuthorsGridSeeds) {
  // The default anchor (authors' grid) against sklearn's mean shift fed with
  // the centres of that grid as explicit seeds.
  run_fixture("meanshift_sklearn_datamin.json", sogmm::BinAnchor::DataMin);
}

TEST(MeanShiftFlat, TwoTightBlobsHandComputed) {
  // 10 points at (0,0) +- 0.01 and 5 at (1,1) +- 0.01, h = 0.2: two modes at the
  // blob means, strengths 10 and 5.
  std::vector<double> p;
  for (int i = 0; i < 10; ++i) p.insert(p.end(), {0.01 * ((i % 3) - 1), 0.01 * ((i % 2) ? 1 : -1)});
  for (int i = 0; i < 5; ++i) p.insert(p.end(), {1.0 + 0.01 * ((i % 3) - 1), 1.0});
  double mx0 = 0, my0 = 0, mx1 = 0;
  for (int i = 0; i < 10; ++i) mx0 += p[2 * i] / 10, my0 += p[2 * i + 1] / 10;
  for (int i = 10; i < 15; ++i) mx1 += p[2 * i] / 5;
  for (auto anchor : {sogmm::BinAnchor::DataMin, sogmm::BinAnchor::Zero}) {
    sogmm::MeanShiftOptions o;
    o.anchor = anchor;
    const auto r = sogmm::mean_shift_flat(p, 0.2, o);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r.strengths[0], 10u);
    EXPECT_EQ(r.strengths[1], 5u);
    EXPECT_NEAR(r.centers[0], mx0, 1e-12);
    EXPECT_NEAR(r.centers[1], my0, 1e-12);
    EXPECT_NEAR(r.centers[2], mx1, 1e-12);
    EXPECT_NEAR(r.centers[3], 1.0, 1e-12);
  }
}

TEST(MeanShiftFlat, SinglePointAndIdenticalPoints) {
  const auto one = sogmm::mean_shift_flat({0.3, 0.7}, 0.05);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one.strengths[0], 1u);
  EXPECT_DOUBLE_EQ(one.centers[0], 0.3);
  EXPECT_DOUBLE_EQ(one.centers[1], 0.7);
  const auto same = sogmm::mean_shift_flat(std::vector<double>(200, 1.25), 0.05);  // 100 copies of (1.25, 1.25)
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same.strengths[0], 100u);
}

TEST(MeanShiftGaussianBlurring, TwoTightBlobs) {
  std::vector<double> p;
  sogmm_test::TestRng r(4);
  for (int i = 0; i < 60; ++i) p.insert(p.end(), {0.005 * r.normal(), 0.005 * r.normal()});
  for (int i = 0; i < 40; ++i) p.insert(p.end(), {1.0 + 0.005 * r.normal(), 0.5 + 0.005 * r.normal()});
  const auto res = sogmm::mean_shift_gaussian_blurring(p, 0.05);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_EQ(res.strengths[0], 60u);
  EXPECT_EQ(res.strengths[1], 40u);
  EXPECT_NEAR(res.centers[0], 0.0, 0.01);
  EXPECT_NEAR(res.centers[2], 1.0, 0.01);
  EXPECT_NEAR(res.centers[3], 0.5, 0.01);
}

TEST(RangeGrayFeatures, HandComputed) {
  const std::vector<float> pts = {3, 4, 0, 0.5f, 1, 2, 2, 0.1f, 0, 0, 2.5f, 1.0f};
  const auto f = sogmm::range_gray_features({pts.data(), 3});
  ASSERT_EQ(f.size(), 6u);
  EXPECT_NEAR(f[0], 5.0, 1e-6);
  EXPECT_NEAR(f[1], 0.5, 1e-7);
  EXPECT_NEAR(f[2], 3.0, 1e-6);
  EXPECT_NEAR(f[3], 0.1, 1e-7);
  EXPECT_NEAR(f[4], 2.5, 1e-6);
  EXPECT_NEAR(f[5], 1.0, 1e-7);
}
