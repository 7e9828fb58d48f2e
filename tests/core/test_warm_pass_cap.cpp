// The warm start's pass limit (WarmStartOptions::max_iter): a warm fit whose
// em.max_iter is left at its default runs warm.max_iter EM passes, one with
// any other em.max_iter (the user's) runs that; a cold fit (and a warm start
// that fell back to a cold one) runs em.max_iter. With tol = 0 EM runs exactly
// its pass limit (EmOptions::tol), so every count below is exact; the counts
// do not depend on the SIMD kernel (sse2, avx2, avx512 alike), since nothing
// here depends on a likelihood's value beyond it being finite.
#include <gtest/gtest.h>

#include "sogmm/error.hpp"
#include "sogmm/fit_record.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/options.hpp"
#include "sogmm/warm_start.hpp"
#include "test_util.hpp"

namespace {

const std::vector<Eigen::Vector4d> kMus = {Eigen::Vector4d(0.0, 0.0, 2.0, 0.2), Eigen::Vector4d(0.5, 0.0, 2.0, 0.4),
                                           Eigen::Vector4d(0.0, 0.5, 2.0, 0.6)};
Eigen::Matrix4d cov() { return Eigen::Vector4d(4e-4, 4e-4, 1e-4, 1e-3).asDiagonal(); }

struct Scene {
  std::vector<float> a = sogmm_test::draw_mixture(kMus, {cov(), cov(), cov()}, {300, 300, 300}, 11, nullptr);
  std::vector<float> b = sogmm_test::draw_mixture(kMus, {cov(), cov(), cov()}, {300, 300, 300}, 12, nullptr);
  sogmm::PointsView va() const { return {a.data(), a.size() / 4}; }
  sogmm::PointsView vb() const { return {b.data(), b.size() / 4}; }
};

sogmm::FitOptions exact_passes(int max_iter = sogmm::EmOptions{}.max_iter) {
  sogmm::FitOptions o;
  o.bandwidth = 0.05;
  o.em.threads = 1;
  o.em.tol = 0.0;  // run the whole pass limit
  o.em.max_iter = max_iter;
  return o;
}

sogmm::WarmStartOptions limit(int max_iter) {
  sogmm::WarmStartOptions w;
  w.max_iter = max_iter;
  return w;
}

}  // namespace

TEST(WarmPassCap, DefaultCapAppliesOnlyToWarmFits) {
  const Scene s;
  const int cap = sogmm::WarmStartOptions{}.max_iter, max_iter = sogmm::EmOptions{}.max_iter;
  ASSERT_GT(cap, 0);
  ASSERT_LT(cap, max_iter);
  const sogmm::FitOptions o = exact_passes();
  const sogmm::Gmm initial = sogmm::fit(s.va(), o).gmm;
  sogmm::WarmStartReport rep;
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, o, {}, {}, &rep).em.iterations, cap);
  EXPECT_GT(rep.kept, 0u);
  EXPECT_EQ(sogmm::fit(s.vb(), o).em.iterations, max_iter);
  // The registry reports the field's default (one source of truth).
  bool listed = false;
  for (const sogmm::OptionSpec& spec : sogmm::option_specs())
    if (spec.key == sogmm::OptionKey::WARM_MAX_ITER) {
      listed = true;
      EXPECT_EQ(spec.get_i64(sogmm::Settings{}), cap);
    }
  EXPECT_TRUE(listed);
}

TEST(WarmPassCap, AnExplicitMaxIterWinsAndZeroLiftsTheCap) {
  const Scene s;
  const sogmm::Gmm initial = sogmm::fit(s.va(), exact_passes()).gmm;
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, exact_passes(), {}, limit(4)).em.iterations, 4);
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, exact_passes(3), {}, limit(4)).em.iterations, 3);
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, exact_passes(11), {}, limit(4)).em.iterations, 11);
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, exact_passes(), {}, limit(0)).em.iterations, sogmm::EmOptions{}.max_iter);
  // A cap above the default limit does not raise it; the report (and the
  // model's fit record, record_fit) names the limit the EM ran under.
  const sogmm::FitResult above = sogmm::fit_warm(s.vb(), initial, exact_passes(), {}, limit(250));
  EXPECT_EQ(above.em.iterations, sogmm::EmOptions{}.max_iter);
  const sogmm::FitResult capped = sogmm::fit_warm(s.vb(), initial, exact_passes(), {}, limit(4));
  EXPECT_EQ(capped.em.max_iter, 4);
  sogmm::Model record;
  sogmm::record_fit(record, capped, exact_passes());
  EXPECT_EQ(record.fit.max_iter, 4);
  sogmm::FitOptions fixed = exact_passes();
  fixed.n_components = initial.size();
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, fixed, {}, limit(4)).em.iterations, 4);
  EXPECT_THROW(sogmm::fit_warm(s.vb(), initial, exact_passes(), {}, limit(-1)), sogmm::Error);
}

// A start 100 m from every point falls back to a cold fit (fit_warm's step
// 1), which is not next to its optimum: it runs max_iter like fit().
TEST(WarmPassCap, ColdFallbackRunsMaxIter) {
  Scene s;
  const sogmm::Gmm initial = sogmm::fit(s.va(), exact_passes()).gmm;
  for (std::size_t i = 0; i < s.b.size(); i += 4) s.b[i] += 100.f;
  sogmm::WarmStartReport rep;
  EXPECT_EQ(sogmm::fit_warm(s.vb(), initial, exact_passes(), {}, limit(4), &rep).em.iterations,
            sogmm::EmOptions{}.max_iter);
  EXPECT_TRUE(rep.cold_fallback);
}
