// Merging models with their metadata (spec/format.md sections 2.1 and 2.2).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "sogmm/inference.hpp"
#include "sogmm/model.hpp"
#include "test_util.hpp"

namespace {

using sogmm::Model;
using sogmm_test::expect_error;
using sogmm_test::set_component;

// One unit-covariance component at x, with a fit record and a camera.
Model fitted(float x, std::uint64_t support, std::int32_t n_iter, bool converged, double log_likelihood) {
  Model m;
  m.gmm.resize(1);
  set_component(m.gmm, 0, 1.0, Eigen::Vector4d(x, 0, 1, 0.5), Eigen::Matrix4d::Identity());
  m.gmm.support_size = support;
  m.fit.known = true;
  m.fit.bandwidth = 0.02;
  m.fit.tol = 1e-3;
  m.fit.max_iter = 100;
  m.fit.n_iter = n_iter;
  m.fit.converged = converged;
  m.fit.log_likelihood = log_likelihood;
  m.fit.seed = 7;
  m.camera.known = true;
  m.camera.camera.fx = 525.0;
  m.pose = std::array<double, 16>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m.key_values = {{"source_depth", "a.png"}};
  return m;
}

std::string value(const Model& m, const std::string& key) {
  for (const auto& kv : m.key_values)
    if (kv.first == key) return kv.second;
  return "(absent)";
}

TEST(ModelMerge, FitRecordHasTheDefinedMeaning) {
  const Model a = fitted(0.f, 100, 60, true, 1.0), b = fitted(1.f, 300, 109, false, 3.0);
  const Model m = sogmm::merge(a, b);
  ASSERT_TRUE(m.fit.known);
  EXPECT_EQ(m.fit.n_iter, 169);  // the total, above max_iter: allowed
  EXPECT_EQ(m.fit.max_iter, 100);
  EXPECT_FALSE(m.fit.converged);  // one fit did not converge
  EXPECT_DOUBLE_EQ(m.fit.log_likelihood, 0.25 * 1.0 + 0.75 * 3.0);  // support-weighted
  EXPECT_TRUE(m.camera.known);
  EXPECT_FALSE(m.pose.has_value());
  EXPECT_EQ(value(m, "merged_fits"), "2");
  EXPECT_EQ(value(m, "source_depth"), "(absent)");
  EXPECT_EQ(value(m, "coordinate_frame"), "(absent)");  // camera frame: not written
  EXPECT_EQ(m.gmm.support_size, 400u);
}

TEST(ModelMerge, CountsFitsAndKeepsTheWorldFrame) {
  Model a = fitted(0.f, 100, 1, true, 0.0), b = fitted(1.f, 100, 1, true, 0.0), c = fitted(2.f, 100, 1, true, 0.0);
  for (Model* m : {&a, &b, &c}) m->key_values.emplace_back("coordinate_frame", "world");
  const Model ab = sogmm::merge(a, b);
  const Model abc = sogmm::merge(ab, c);
  EXPECT_EQ(value(abc, "coordinate_frame"), "world");
  EXPECT_EQ(value(abc, "merged_fits"), "3");
  EXPECT_EQ(value(sogmm::merge(ab, ab), "merged_fits"), "4");
  EXPECT_EQ(sogmm::coordinate_frame(abc), "world");
}

TEST(ModelMerge, RefusesModelsInDifferentFrames) {
  Model a = fitted(0.f, 100, 1, true, 0.0);
  const Model b = fitted(1.f, 100, 1, true, 0.0);
  a.key_values.emplace_back("coordinate_frame", "world");
  expect_error([&] { sogmm::merge(a, b); }, sogmm::ErrorCode::InvalidArgument, {"frame"}, "merge across frames");
}

TEST(ModelMerge, DropsWhatTheModelsDoNotShare) {
  Model a = fitted(0.f, 100, 1, true, 0.0), b = fitted(1.f, 100, 1, true, 0.0);
  b.fit.bandwidth = 0.03;  // another fit setting: no common fit record
  b.camera.camera.fx = 500.0;
  const Model m = sogmm::merge(a, b);
  EXPECT_FALSE(m.fit.known);
  EXPECT_FALSE(m.camera.known);
  b = fitted(1.f, 100, 1, true, 0.0);
  b.fit.known = false;
  EXPECT_FALSE(sogmm::merge(a, b).fit.known);
}

TEST(ModelMerge, IterationTotalSaturates) {
  const Model a = fitted(0.f, 1, std::numeric_limits<std::int32_t>::max(), true, 0.0), b = fitted(1.f, 1, 5, true, 0.0);
  EXPECT_EQ(sogmm::merge(a, b).fit.n_iter, std::numeric_limits<std::int32_t>::max());
}

// A file may hold any int32 as n_iter: a negative one counts as 0, so the
// total never falls (the sum of two INT32_MIN would wrap to 0 or worse).
TEST(ModelMerge, NegativeIterationCountsAsZero) {
  const Model a = fitted(0.f, 1, std::numeric_limits<std::int32_t>::min(), true, 0.0),
              b = fitted(1.f, 1, 5, true, 0.0);
  EXPECT_EQ(sogmm::merge(a, b).fit.n_iter, 5);
  EXPECT_EQ(sogmm::merge(a, a).fit.n_iter, 0);
}

// merged_fits read from files may hold up to 19 digits; a sum beyond 2^64 - 1
// is a Limit error, not a wrapped count.
TEST(ModelMerge, FitCountOverflowIsALimitError) {
  Model a = fitted(0.f, 1, 1, true, 0.0), b = fitted(1.f, 1, 1, true, 0.0);
  a.key_values.emplace_back("merged_fits", "9999999999999999999");
  b.key_values.emplace_back("merged_fits", "9999999999999999999");
  expect_error([&] { sogmm::merge(a, b); }, sogmm::ErrorCode::Limit, {"merged_fits"}, "merged_fits overflow");
  b.key_values.back().second = "2";
  EXPECT_EQ(value(sogmm::merge(a, b), "merged_fits"), "10000000000000000001");
}

}  // namespace
