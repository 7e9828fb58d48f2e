// Numerically hostile clouds: degenerate geometry (all points identical,
// two distinct points, collinear, coplanar), extreme scales (millimetres,
// kilometres) and constant gray. Both the self-organizing and the fixed-K fit
// must return a valid (regularised) model, never NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/sogmm.h"

namespace {

using Cloud = std::vector<float>;

struct Case {
  std::string name;
  std::function<Cloud()> make;
};

Cloud generate(std::size_t n, std::uint32_t seed, const std::function<void(std::mt19937&, float*)>& point) {
  std::mt19937 rng(seed);
  Cloud c(4 * n);
  for (std::size_t i = 0; i < n; ++i) point(rng, &c[4 * i]);
  return c;
}

float u(std::mt19937& r, float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(r); }

std::vector<Case> cases() {
  const std::size_t n = 400;
  return {
      {"all_identical", [=] { return generate(n, 1, [](std::mt19937&, float* p) { p[0] = 0.3f; p[1] = -0.2f; p[2] = 1.5f; p[3] = 0.5f; }); }},
      {"all_identical_at_origin_gray_zero", [=] { return generate(n, 1, [](std::mt19937&, float* p) { p[0] = p[1] = p[2] = p[3] = 0.0f; }); }},
      {"two_distinct_points", [=] {
         return generate(n, 2, [](std::mt19937& r, float* p) {
           const bool a = r() & 1;
           p[0] = a ? 0.1f : 0.6f; p[1] = 0.0f; p[2] = a ? 1.0f : 2.0f; p[3] = a ? 0.2f : 0.8f;
         });
       }},
      {"collinear", [=] {
         return generate(n, 3, [](std::mt19937& r, float* p) {
           const float t = u(r, 0.0f, 1.0f);
           p[0] = t; p[1] = 2 * t; p[2] = 1.0f + t; p[3] = 0.5f;
         });
       }},
      {"collinear_gray_varies", [=] {
         return generate(n, 4, [](std::mt19937& r, float* p) {
           const float t = u(r, 0.0f, 1.0f);
           p[0] = t; p[1] = 0.0f; p[2] = 1.0f; p[3] = t;
         });
       }},
      {"coplanar", [=] {
         return generate(n, 5, [](std::mt19937& r, float* p) {
           p[0] = u(r, -1, 1); p[1] = u(r, -1, 1); p[2] = 2.0f; p[3] = u(r, 0, 1);
         });
       }},
      {"gray_constant", [=] {
         return generate(n, 6, [](std::mt19937& r, float* p) {
           p[0] = u(r, -1, 1); p[1] = u(r, -1, 1); p[2] = u(r, 0.5f, 3); p[3] = 0.42f;
         });
       }},
      {"millimetre_extent", [=] {
         return generate(n, 7, [](std::mt19937& r, float* p) {
           p[0] = u(r, 0, 2e-3f); p[1] = u(r, 0, 2e-3f); p[2] = 1.0f + u(r, 0, 2e-3f); p[3] = u(r, 0, 1);
         });
       }},
      {"micrometre_extent", [=] {
         return generate(n, 8, [](std::mt19937& r, float* p) {
           p[0] = u(r, 0, 2e-6f); p[1] = u(r, 0, 2e-6f); p[2] = 1.0f + u(r, 0, 2e-6f); p[3] = 0.5f;
         });
       }},
      {"kilometre_extent", [=] {
         return generate(n, 9, [](std::mt19937& r, float* p) {
           p[0] = u(r, -1e3f, 1e3f); p[1] = u(r, -1e3f, 1e3f); p[2] = u(r, 0, 1e3f); p[3] = u(r, 0, 1);
         });
       }},
      {"kilometres_away_millimetre_extent", [=] {
         return generate(n, 10, [](std::mt19937& r, float* p) {
           p[0] = 5e3f + u(r, 0, 1e-3f); p[1] = 5e3f; p[2] = 5e3f + u(r, 0, 1e-3f); p[3] = u(r, 0, 1);
         });
       }},
  };
}

void expect_valid(const sogmm::Gmm& g, std::size_t n, const std::string& what) {
  EXPECT_EQ(sogmm::validation_error(g), "") << what;
  EXPECT_GE(g.size(), 1u) << what;
  EXPECT_LE(g.size(), n) << what;
  for (float v : g.weights) ASSERT_TRUE(std::isfinite(v)) << what;
  for (float v : g.means) ASSERT_TRUE(std::isfinite(v)) << what;
  for (float v : g.covariances) ASSERT_TRUE(std::isfinite(v)) << what;
}

// One fit: it must succeed with a valid model (never NaN).
void run(const Case& c, std::size_t k, sogmm::ModeCounter counter) {
  const Cloud cloud = c.make();
  sogmm::PointsView view{cloud.data(), cloud.size() / 4};
  sogmm::FitOptions o;
  o.n_components = k;
  o.mode_counter = counter;
  o.em.threads = 1;
  o.em.max_iter = 50;
  const std::string what = c.name + (k ? " K=" + std::to_string(k) : std::string(" self-organizing")) +
                           (counter == sogmm::ModeCounter::GaussianBlurring ? " (blurring)" : "");
  try {
    const sogmm::FitResult r = sogmm::fit(view, o);
    expect_valid(r.gmm, view.size, what);
    EXPECT_FALSE(std::isnan(r.em.log_likelihood)) << what;
  } catch (const sogmm::Error& e) {
    ADD_FAILURE() << what << ": fit failed: " << e.what();
  }
}

class Hostile : public ::testing::TestWithParam<std::size_t> {};

TEST_P(Hostile, FitGivesAValidModel) {
  const Case c = cases()[GetParam()];
  run(c, 0, sogmm::ModeCounter::FlatBinned);
  run(c, 0, sogmm::ModeCounter::GaussianBlurring);
  for (std::size_t k : {1, 2, 5, 16}) run(c, k, sogmm::ModeCounter::FlatBinned);
}

INSTANTIATE_TEST_SUITE_P(core, Hostile, ::testing::Range<std::size_t>(0, cases().size()),
                         [](const ::testing::TestParamInfo<std::size_t>& i) { return cases()[i.param].name; });

// The same through the C API, which must never return a model with NaN.
TEST(CapiHostile, FitNeverReturnsNaN) {
  for (const Case& c : cases()) {
    const Cloud cloud = c.make();
    for (std::size_t k : {0, 3}) {
      sogmm_model* m = nullptr;
      sogmm_options* o = nullptr;
      ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
      sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1);
      sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, static_cast<std::int64_t>(k));
      const sogmm_status s = sogmm_fit_points_f32(&m, cloud.data(), cloud.size() / 4, nullptr, o);
      ASSERT_EQ(s, SOGMM_OK) << c.name << " K=" << k << ": " << sogmm_last_error();
      std::size_t mm = 0;
      ASSERT_EQ(sogmm_model_n_components(m, &mm), SOGMM_OK);
      std::vector<float> cov(16 * mm);
      ASSERT_EQ(sogmm_model_get_covariances_f32(m, cov.data(), cov.size()), SOGMM_OK);
      for (float v : cov) EXPECT_TRUE(std::isfinite(v)) << c.name;
      double ll = 0;
      ASSERT_EQ(sogmm_model_get_info_f64(m, SOGMM_INFO_FIT_LOG_LIKELIHOOD, &ll), SOGMM_OK);
      EXPECT_FALSE(std::isnan(ll)) << c.name;
      // Inference on the fitted model at the data itself: no NaN.
      std::vector<double> score(cloud.size() / 4);
      ASSERT_EQ(sogmm_model_score_samples_f32(m, cloud.data(), score.size(), 4, nullptr, score.data()), SOGMM_OK);
      for (double s2 : score) EXPECT_FALSE(std::isnan(s2)) << c.name;
      sogmm_model_free(m);
      sogmm_options_free(o);
    }
  }
}

}  // namespace
