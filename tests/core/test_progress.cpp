// The progress sink (sogmm/progress.hpp): reports never change a result,
// whatever the thread count; a true return stops the fit or the sampling
// with Error(Cancelled) in the stage where it was given; scopes nest.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/progress.hpp"
#include "test_util.hpp"

namespace {

std::vector<float> cloud() {
  std::vector<Eigen::Vector4d> mus{{0, 0, 1, 0.2}, {0.5, 0.1, 1.5, 0.8}, {-0.4, 0.3, 1.2, 0.5}};
  std::vector<Eigen::Matrix4d> covs(3, 0.002 * Eigen::Matrix4d::Identity());
  return sogmm_test::draw_mixture(mus, covs, {3000, 2000, 2500}, 11);
}

sogmm::FitOptions options(int threads) {
  sogmm::FitOptions o;
  o.bandwidth = 0.05;
  o.seed = 9;
  o.em.threads = threads;
  o.em.tol = 1e-300;  // EM stops at max_iter or at an exact fixed point
  o.em.max_iter = 12;
  return o;
}

// Cancels at the first report of `stage` whose step is at least `step`.
struct CancelAt {
  sogmm::Stage stage;
  std::uint64_t step;
  std::vector<sogmm::Progress>* seen;
  bool operator()(const sogmm::Progress& p) const {
    seen->push_back(p);
    return p.stage == stage && p.step >= step;
  }
};

}  // namespace

TEST(Progress, SinkChangesNoResultForAnyThreadCount) {
  const std::vector<float> pts = cloud();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  const sogmm::FitResult plain = sogmm::fit(v, options(1));
  for (int threads : {1, 2, 3}) {
    std::vector<sogmm::Progress> seen;
    const sogmm::FitResult r = sogmm::fit(v, options(threads), [&](const sogmm::Progress& p) {
      seen.push_back(p);
      return false;
    });
    EXPECT_TRUE(sogmm_test::bit_identical(plain.gmm, r.gmm)) << threads << " threads";
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.front().stage, sogmm::Stage::ModeCount);
    // Within a stage (until the stage changes) steps never decrease.
    for (std::size_t i = 1; i < seen.size(); ++i) {
      if (seen[i].stage == seen[i - 1].stage) {
        EXPECT_GE(seen[i].step, seen[i - 1].step) << i;
      }
    }
    EXPECT_EQ(seen.back().stage, sogmm::Stage::Em);
    EXPECT_EQ(seen.back().step, static_cast<std::uint64_t>(r.em.iterations));
    EXPECT_EQ(seen.back().total, 12u);
    EXPECT_EQ(seen.back().log_likelihood, r.em.log_likelihood);
  }
}

TEST(Progress, TrueCancelsInTheStageItWasGiven) {
  const std::vector<float> pts = cloud();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  struct Case {
    sogmm::Stage stage;
    std::uint64_t step;
    const char* message;
  };
  for (const Case& c : {Case{sogmm::Stage::ModeCount, 0, "the mode count"}, Case{sogmm::Stage::Seeding, 0, "seeding"},
                        Case{sogmm::Stage::Em, 3, "EM iteration 3"}}) {
    for (int threads : {1, 2}) {
      std::vector<sogmm::Progress> seen;
      try {
        sogmm::fit(v, options(threads), CancelAt{c.stage, c.step, &seen});
        ADD_FAILURE() << c.message << ": not cancelled";
      } catch (const sogmm::Error& e) {
        EXPECT_EQ(e.code(), sogmm::ErrorCode::Cancelled);
        EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
      }
      ASSERT_FALSE(seen.empty());
      EXPECT_EQ(seen.back().stage, c.stage) << "no report after the cancel";
    }
  }
}

TEST(Progress, SamplingReportsAndCancels) {
  const std::vector<float> pts = cloud();
  const sogmm::FitResult r = sogmm::fit({pts.data(), pts.size() / 4}, options(2));
  std::vector<float> out(4 * 1000, -1.0f), ref(4 * 1000);
  sogmm::sample(r.gmm, 1000, 5, 4, ref.data());
  std::vector<sogmm::Progress> seen;
  {
    const sogmm::ProgressScope scope(CancelAt{sogmm::Stage::Sampling, 1000, &seen});  // never cancels
    sogmm::sample(r.gmm, 1000, 5, 4, out.data());
  }
  EXPECT_EQ(out, ref);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.front().stage, sogmm::Stage::Sampling);
  EXPECT_EQ(seen.front().total, 1000u);
  const sogmm::ProgressScope scope(CancelAt{sogmm::Stage::Sampling, 0, &seen});
  EXPECT_THROW(sogmm::sample(r.gmm, 1000, 5, 4, out.data()), sogmm::Error);
}

TEST(Progress, ScopesNestAndAnEmptySinkInstallsNothing) {
  const std::vector<float> pts = cloud();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  int outer = 0, inner = 0;
  const sogmm::ProgressScope outer_scope([&](const sogmm::Progress&) { return ++outer, false; });
  {
    const sogmm::ProgressScope inner_scope([&](const sogmm::Progress&) { return ++inner, false; });
    sogmm::fit(v, options(1));
  }
  EXPECT_GT(inner, 0);
  EXPECT_EQ(outer, 0);
  sogmm::fit(v, options(1), {});  // an empty sink: the outer scope still reports
  EXPECT_GT(outer, 0);
}

// Inside a sink, the thread has no sink: a fit the sink runs reports neither
// to it (which recursed without bound when the nested fit ran again from the
// report) nor anywhere, and the outer reports go on after it (issue 36).
TEST(Progress, CallsMadeInsideASinkRunWithoutOne) {
  const std::vector<float> pts = cloud();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  int depth = 0, max_depth = 0, calls = 0;
  std::size_t nested_k = 0;
  const sogmm::ProgressSink sink = [&](const sogmm::Progress&) {
    ++calls;
    max_depth = std::max(max_depth, ++depth);
    if (depth < 3) nested_k = sogmm::fit(v, options(1)).gmm.size();  // no sink of its own
    --depth;
    return false;
  };
  sogmm::fit(v, options(1), sink);
  EXPECT_GT(calls, 1);
  EXPECT_EQ(max_depth, 1);
  EXPECT_GT(nested_k, 0u);
}
