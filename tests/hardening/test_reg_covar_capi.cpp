// SOGMM_OPT_REG_COVAR at the C boundary (issue 14): SOGMM_REG_COVAR_AUTO is
// the default and can be set back; any other negative value, NaN or an
// infinity is refused by name and leaves the options unchanged; a fit
// records the floors it used (FIT_REG_COVAR = the spatial floor, key_values
// reg_covar_gray and reg_covar_source), and they survive a file round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "capi_calls.hpp"
#include "sogmm/sogmm.h"

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

double reg_covar(const sogmm_options* o) {
  double v = 0.0;
  EXPECT_EQ(sogmm_options_get_f64(o, SOGMM_OPT_REG_COVAR, &v), SOGMM_OK);
  return v;
}

std::string value(const sogmm_model* m, const char* key) {
  const char* v = nullptr;
  return sogmm_model_get_value(m, key, &v) == SOGMM_OK ? std::string(v) : std::string("<absent>");
}

// 200 points on a 2 x 1 grid plane (x `scale`) with gray in [0, 1].
std::vector<float> plane(float scale) {
  std::vector<float> p;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 10; ++j)
      p.insert(p.end(), {scale * (0.1f * i - 1.0f), scale * (0.1f * j - 0.5f), scale * 0.001f * ((i * 7 + j * 3) % 5),
                         static_cast<float>((i + j) % 11) / 10.0f});
  return p;
}

}  // namespace

TEST(CapiRegCovar, AutoIsTheDefaultAndCanBeSetBack) {
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  EXPECT_EQ(reg_covar(o), SOGMM_REG_COVAR_AUTO);
  ASSERT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, 1e-4), SOGMM_OK);
  EXPECT_EQ(reg_covar(o), 1e-4);
  ASSERT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, SOGMM_REG_COVAR_AUTO), SOGMM_OK);
  EXPECT_EQ(reg_covar(o), SOGMM_REG_COVAR_AUTO);
  sogmm_options_free(o);
}

TEST(CapiRegCovar, NegativeNanAndInfinitiesAreRefusedByName) {
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, 2e-6), SOGMM_OK);
  for (double bad : {-1e-6, -0.5, -2.0, -HUGE_VAL, HUGE_VAL, std::nan("")}) {
    EXPECT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, bad), SOGMM_E_INVALID_ARG) << bad;
    const std::string e = sogmm_last_error();
    EXPECT_TRUE(has(e, "SOGMM_OPT_REG_COVAR") && has(e, ">= 0") && has(e, "SOGMM_REG_COVAR_AUTO")) << e;
    EXPECT_EQ(reg_covar(o), 2e-6) << "a refused value changed the options";
  }
  sogmm_options_free(o);
}

TEST(CapiRegCovar, FitRecordsTheFloorsItUsed) {
  const std::vector<float> room = plane(1.0f), km = plane(1000.0f);
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 1), SOGMM_OK);
  struct Case {
    const std::vector<float>* points;
    double set;  // SOGMM_OPT_REG_COVAR
    double spatial;
    const char* gray;
    const char* source;
  } cases[] = {{&room, SOGMM_REG_COVAR_AUTO, 1e-6, "1e-06", "auto"},
               {&km, SOGMM_REG_COVAR_AUTO, 1.0, "1e-06", "auto"},  // median distance ~600 m: 10^3
               {&km, 1e-4, 1e-4, "0.0001", "user"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.source) + " " + std::to_string(c.spatial));
    ASSERT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_REG_COVAR, c.set), SOGMM_OK);
    sogmm_model* m = nullptr;
    ASSERT_EQ(sogmm_test::fit_fixed_k(&m, c.points->data(), c.points->size() / 4, 4, o), SOGMM_OK)
        << sogmm_last_error();
    sogmm_buffer* buf = nullptr;
    ASSERT_EQ(sogmm_model_save_to_memory(&buf, m, nullptr), SOGMM_OK);
    sogmm_model* back = nullptr;
    ASSERT_EQ(sogmm_model_load_from_memory(&back, sogmm_buffer_data(buf), sogmm_buffer_size(buf), nullptr), SOGMM_OK);
    for (const sogmm_model* x : {static_cast<const sogmm_model*>(m), static_cast<const sogmm_model*>(back)}) {
      double v = 0.0;
      ASSERT_EQ(sogmm_model_get_info_f64(x, SOGMM_INFO_FIT_REG_COVAR, &v), SOGMM_OK);
      EXPECT_EQ(v, c.spatial);
      EXPECT_EQ(value(x, "reg_covar_gray"), c.gray);
      EXPECT_EQ(value(x, "reg_covar_source"), c.source);
    }
    sogmm_model_free(back);
    sogmm_buffer_free(buf);
    sogmm_model_free(m);
  }
  sogmm_options_free(o);
}
